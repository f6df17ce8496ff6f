# FindODE: the Open Dynamics Engine, which ships only a pkg-config file.
# Provides the imported target ODE::ODE and ODE_FOUND, ODE_VERSION, ODE_PRECISION.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(PC_ODE QUIET ode)
endif()

find_path(ODE_INCLUDE_DIR ode/ode.h HINTS ${PC_ODE_INCLUDE_DIRS})
find_library(ODE_LIBRARY NAMES ode HINTS ${PC_ODE_LIBRARY_DIRS})
set(ODE_VERSION ${PC_ODE_VERSION})
if(PC_ODE_FOUND)
  pkg_get_variable(ODE_PRECISION ode precision)
endif()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(ODE
  REQUIRED_VARS ODE_LIBRARY ODE_INCLUDE_DIR
  VERSION_VAR ODE_VERSION)

if(ODE_FOUND AND NOT TARGET ODE::ODE)
  add_library(ODE::ODE UNKNOWN IMPORTED)
  set_target_properties(ODE::ODE PROPERTIES
    IMPORTED_LOCATION "${ODE_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${ODE_INCLUDE_DIR}")
  # the headers pick the precision from this define; Debian's build is double precision
  if(ODE_PRECISION STREQUAL "dSINGLE")
    set_property(TARGET ODE::ODE PROPERTY INTERFACE_COMPILE_DEFINITIONS dSINGLE)
  else()
    set_property(TARGET ODE::ODE PROPERTY INTERFACE_COMPILE_DEFINITIONS dDOUBLE)
  endif()
endif()
mark_as_advanced(ODE_INCLUDE_DIR ODE_LIBRARY)
