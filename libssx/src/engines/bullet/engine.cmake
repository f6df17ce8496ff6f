# The Bullet engine's sources and library (included by libssx/CMakeLists.txt).
target_sources(ssx PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/bullet_class.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bullet_contacts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bullet_engine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bullet_joints.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bullet_rays.cpp)
target_link_libraries(ssx PRIVATE ssx_bullet)
