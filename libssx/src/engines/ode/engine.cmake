# The ODE engine's sources and library (included by libssx/CMakeLists.txt).
target_sources(ssx PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/ode_class.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_contacts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_engine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_free_bodies.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_joints.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_meshes.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_overlaps.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ode_rays.cpp)
target_link_libraries(ssx PRIVATE ODE::ODE)
