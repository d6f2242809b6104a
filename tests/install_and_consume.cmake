# ctest's install_and_consume (tests/CMakeLists.txt): installs the build tree into a prefix
# inside the build directory, builds examples/ as a standalone project against it
# (find_package(vertexflow CONFIG REQUIRED)), and runs the example on a bundled mesh. Any
# failing step fails the test.
#
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -DCXX_COMPILER=...
#         [-DMAKE_PROGRAM=...] [-DBUILD_TYPE=...] [-DEXTRA_FLAGS=...] -P install_and_consume.cmake
foreach(variable BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${variable} OR "${${variable}}" STREQUAL "")
    message(FATAL_ERROR "install_and_consume: -D${variable}=... is required")
  endif()
endforeach()

set(prefix "${WORK_DIR}/prefix")
set(example_build "${WORK_DIR}/example-build")
set(output "${WORK_DIR}/spot.ply")
# A clean start: nothing left from an earlier run may stand in for this one's results.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(step name)
  message(STATUS "install_and_consume: ${name}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "install_and_consume: ${name} failed (${result}): ${ARGN}")
  endif()
endfunction()

set(config_args)
if(BUILD_TYPE)
  set(config_args --config "${BUILD_TYPE}")
endif()
step("install into ${prefix}" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" ${config_args})

foreach(file bin/vertexflow include/vertexflow/io.h)
  if(NOT EXISTS "${prefix}/${file}")
    message(FATAL_ERROR "install_and_consume: ${prefix}/${file} was not installed")
  endif()
endforeach()

set(configure_args -S "${SOURCE_DIR}/examples" -B "${example_build}" -G "${GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}")
if(MAKE_PROGRAM)
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(BUILD_TYPE)
  list(APPEND configure_args "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}")
endif()
if(EXTRA_FLAGS)  # the sanitizers of a VERTEXFLOW_SANITIZE build, which the static libraries need
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=${EXTRA_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${EXTRA_FLAGS}")
endif()
step("configure examples/ against the installed package" "${CMAKE_COMMAND}" ${configure_args})

set(build_args --build "${example_build}")
if(BUILD_TYPE)
  list(APPEND build_args --config "${BUILD_TYPE}")
endif()
step("build examples/" "${CMAKE_COMMAND}" ${build_args})

# The example lands in <example build>/bin (a multi-config generator adds <config>/).
file(GLOB_RECURSE example LIST_DIRECTORIES false "${example_build}/bin/example_read_and_convert*")
if(NOT example)
  message(FATAL_ERROR "install_and_consume: no example_read_and_convert under ${example_build}/bin")
endif()
list(GET example 0 example)
step("run ${example}" "${example}" "${SOURCE_DIR}/data/spot.obj" "${output}")
if(NOT EXISTS "${output}")
  message(FATAL_ERROR "install_and_consume: the example exited 0 but wrote no ${output}")
endif()
file(SIZE "${output}" size)
if(size EQUAL 0)
  message(FATAL_ERROR "install_and_consume: ${output} is empty")
endif()
message(STATUS "install_and_consume: ${output} (${size} bytes)")
