# Installs the ssx build into a temporary prefix, then, against that installation only:
#  - configures, builds and runs a consumer program (find_package(ssx), ssx::ssx);
#  - builds the out-of-tree plugin in examples/custom_plugin with ssx_add_plugin, and runs a
#    scene that loads it with the installed `ssx run`;
#  - builds the out-of-tree controller in examples/custom_controller against ssx::quadrotor, and
#    runs its scene.
# Run with cmake -P (see tests/CMakeLists.txt).
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

run(${CMAKE_COMMAND} --install ${SSX_BUILD_DIR} --prefix ${prefix})

# a program linking libssx
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/consumer -G ${GENERATOR}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/consumer)
run(${WORK_DIR}/consumer/consumer)

# an out-of-tree plugin, run by the installed command
run(${CMAKE_COMMAND} -S ${PLUGIN_SOURCE_DIR} -B ${WORK_DIR}/plugin -G ${GENERATOR}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/plugin)
run(${prefix}/bin/ssx plugins --plugin-path ${WORK_DIR}/plugin)
if(NOT last_output MATCHES "libssx_orbit.so: ok" OR NOT last_output MATCHES "driver orbit")
  message(FATAL_ERROR "the installed ssx does not list the orbit plugin")
endif()
# its declared parameters, as the installed command lists them
run(${prefix}/bin/ssx plugins --plugin-path ${WORK_DIR}/plugin --params orbit)
if(NOT last_output MATCHES "\\| `orbit_period` \\| real \\| s \\| `8` \\| > 0 \\|")
  message(FATAL_ERROR "ssx plugins --params orbit does not list orbit_period")
endif()
run(${prefix}/bin/ssx run ${PLUGIN_SOURCE_DIR}/orbit_scene.xml --fast --plugin-path ${WORK_DIR}/plugin)
if(NOT last_output MATCHES "steps 2400, simulated 12.000 s")
  message(FATAL_ERROR "the orbit scene did not run its 12 s")
endif()
# the logger wrote 20 rows a second for each of the three orbiters, and closed the file
file(STRINGS ${WORK_DIR}/ssx-out/orbit_scene/orbit_poses.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 721)
  message(FATAL_ERROR "orbit_poses.csv has ${n} lines, expected 1 + 3 * 20 * 12 = 721")
endif()

# a driver with its own controller on the installed quadrotor parts (ssx::quadrotor)
run(${CMAKE_COMMAND} -S ${CONTROLLER_SOURCE_DIR} -B ${WORK_DIR}/controller -G ${GENERATOR}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/controller)
run(${prefix}/bin/ssx plugins --plugin-path ${WORK_DIR}/controller --params pd_quadrotor)
if(NOT last_output MATCHES "\\*\\*controller \\(geometric\\)\\*\\*" OR NOT last_output MATCHES "\\| `kr` \\|")
  message(FATAL_ERROR "ssx plugins --params pd_quadrotor does not list the controller's part")
endif()
run(${prefix}/bin/ssx run ${CONTROLLER_SOURCE_DIR}/pd_scene.xml --fast --duration 2 --plugin-path ${WORK_DIR}/controller)
if(NOT last_output MATCHES "simulated 2.000 s")
  message(FATAL_ERROR "the custom controller's scene did not run its 2 s")
endif()
