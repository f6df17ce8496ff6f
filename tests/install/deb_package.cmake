# Makes the Debian package with `cpack -G DEB` from the build, checks its dependencies, unpacks it
# (dpkg-deb -x, no root needed) and runs, from the unpacked tree only:
#  - the installed `ssx run` on an installed example scene;
#  - a scene that names an installed artifact type without a file;
#  - the Python module, importing numpy, stepping an installed scene (when it was built).
# Run with cmake -P (see tests/CMakeLists.txt).
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

function(expect pattern what)
  if(NOT last_output MATCHES "${pattern}")
    message(FATAL_ERROR "${what}: no match for '${pattern}' in:\n${last_output}")
  endif()
endfunction()

run(${CPACK_COMMAND} -G DEB --config ${SSX_BUILD_DIR}/CPackConfig.cmake -B ${WORK_DIR}/out)
file(GLOB debs ${WORK_DIR}/out/ssx_*.deb)
list(LENGTH debs n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one ssx_*.deb in ${WORK_DIR}/out, found ${n}")
endif()

# the dependencies: the shared libraries the package links (found by dpkg-shlibdeps) and Python's
run(dpkg-deb --field ${debs} Depends)
foreach(dep "libode8" "libpugixml1v5" "libpng16-16" "libstdc\\+\\+6")
  expect("${dep} \\(>= " "Depends")
endforeach()
if(EXPECT_PYTHON)
  expect("python3 \\(>= 3\\.[0-9]+\\), python3 \\(<< 3\\.[0-9]+\\), python3-numpy" "Depends")
endif()

set(root ${WORK_DIR}/root)
run(dpkg-deb -x ${debs} ${root})
foreach(f usr/bin/ssx usr/bin/ssx_rt_study usr/bin/ssx_fidelity_eight usr/share/ssx/artifacts/mk_quad.xml
          usr/share/ssx/scenes/quad_swarm.xml usr/share/ssx/ground/foraging.xml usr/lib/ssx/plugins/libssx_quadrotor.so)
  if(NOT EXISTS ${root}/${f})
    message(FATAL_ERROR "the package has no /${f}")
  endif()
endforeach()

# an installed example scene, run by the installed command (its library, plugins and artifact
# files all from the unpacked tree)
run(${root}/usr/bin/ssx run ${root}/usr/share/ssx/scenes/quad_hover.xml --fast --duration 2)
expect("steps 1000, simulated 2.000 s" "ssx run quad_hover.xml")

# an artifact type by name only
file(WRITE ${WORK_DIR}/by_name.xml [=[<scene>
  <environment timestep="0.002" duration="1"/>
  <type name="crazyflie"/>
  <ground/>
  <artifact name="cf" type="crazyflie" xyz="0 0 0.02"><driver offset="0 0 0.5"/></artifact>
</scene>]=])
run(${root}/usr/bin/ssx validate ${WORK_DIR}/by_name.xml)
run(${root}/usr/bin/ssx run ${WORK_DIR}/by_name.xml --fast)
expect("steps 500, simulated 1.000 s" "ssx run by_name.xml")

# a study program reads the installed artifacts
run(${root}/usr/bin/ssx_rt_study --n 4 --samples 20 --fast)
expect("n=4 samples=20 median_ms=" "ssx_rt_study")

if(EXPECT_PYTHON)
  file(GLOB pydirs ${root}/usr/lib/python3*/dist-packages)
  # (a script file: semicolons in an argument would split it into a CMake list)
  file(WRITE ${WORK_DIR}/use_module.py [=[
import ssx, numpy
d = ssx.data_directory()
print("data", d)
env = ssx.load_scene(d / "scenes" / "quad_hover.xml", threads=1)
env.step(500)
p = env.positions()
print("module", ssx.__file__)
print("rows", p.shape[0], "z_above", bool((p[:, 2] > 0.3).all()))
]=])
  run(${CMAKE_COMMAND} -E env PYTHONPATH=${pydirs} PYTHONDONTWRITEBYTECODE=1 ${PYTHON} ${WORK_DIR}/use_module.py)
  expect("data ${root}/usr/share/ssx" "ssx.data_directory()")
  expect("module ${root}/usr/lib/python3" "the module imported")
  expect("rows 3 z_above True" "the quadrotors took off")
endif()
