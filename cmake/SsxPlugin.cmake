# ssx_add_plugin(NAME <name> SOURCES <files>... [OUTPUT_DIRECTORY <dir>] [INSTALL_DESTINATION <dir>] [NO_INSTALL])
#
# Builds an ssx plugin library libssx_<name>.so from SOURCES, linked to ssx::ssx, with hidden
# visibility (only the manifest symbol that SSX_PLUGIN writes is exported). A scene names it with
# plugin="<name>". The target is called ssx_plugin_<name>.
#
# OUTPUT_DIRECTORY: where the library is written (default: the current binary directory).
# INSTALL_DESTINATION: where `cmake --install` puts it (default: <libdir>/ssx/plugins).
function(ssx_add_plugin)
  cmake_parse_arguments(PLUGIN "NO_INSTALL" "NAME;OUTPUT_DIRECTORY;INSTALL_DESTINATION" "SOURCES" ${ARGN})
  if(NOT PLUGIN_NAME OR NOT PLUGIN_SOURCES)
    message(FATAL_ERROR "ssx_add_plugin: NAME and SOURCES are required")
  endif()
  set(target ssx_plugin_${PLUGIN_NAME})
  add_library(${target} MODULE ${PLUGIN_SOURCES})
  target_link_libraries(${target} PRIVATE ssx::ssx)
  set_target_properties(${target} PROPERTIES
    OUTPUT_NAME ssx_${PLUGIN_NAME}
    PREFIX "lib"
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  if(PLUGIN_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${PLUGIN_OUTPUT_DIRECTORY})
  endif()
  if(NOT PLUGIN_NO_INSTALL)
    include(GNUInstallDirs)
    if(NOT PLUGIN_INSTALL_DESTINATION)
      set(PLUGIN_INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/ssx/plugins)
    endif()
    install(TARGETS ${target} LIBRARY DESTINATION ${PLUGIN_INSTALL_DESTINATION})
  endif()
endfunction()
