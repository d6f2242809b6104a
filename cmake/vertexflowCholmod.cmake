# Defines the imported target cholmod::cholmod (CHOLMOD, SuiteSparse: the flow's sparse
# Cholesky). Debian ships no CMake config for it. Included by the top-level CMakeLists.txt and
# by the installed vertexflowConfig.cmake (the static library links CHOLMOD, so every program
# that links vertexflow::vertexflow links CHOLMOD too): one definition for both.
#
# Sets VERTEXFLOW_CHOLMOD_FOUND (TRUE or FALSE); the includer decides whether a missing CHOLMOD
# is fatal. Does nothing when cholmod::cholmod already exists.
if(TARGET cholmod::cholmod)
  set(VERTEXFLOW_CHOLMOD_FOUND TRUE)
  return()
endif()

find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
if(NOT CHOLMOD_INCLUDE_DIR OR NOT CHOLMOD_LIBRARY)
  set(VERTEXFLOW_CHOLMOD_FOUND FALSE)
  return()
endif()
set(VERTEXFLOW_CHOLMOD_FOUND TRUE)

add_library(cholmod::cholmod INTERFACE IMPORTED)
set_target_properties(cholmod::cholmod PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
                                                  INTERFACE_LINK_LIBRARIES "${CHOLMOD_LIBRARY}")

# CHOLMOD reaches BLAS through Debian's libblas.so.3 alternative, which is the pthread build of
# OpenBLAS when that is installed. We call BLAS from one thread only (flow_solver.cpp), yet that
# build starts a thread per core as it is loaded, before main(); under an address-space limit
# (`ulimit -v`) those threads retry their 128 MB buffers forever, so the process never exits,
# or OpenBLAS raises SIGINT when it cannot start them (issue 12). So whatever links CHOLMOD also
# needs the serial build's libblas/liblapack itself (scripts/setup.sh installs it), found through
# the executable's rpath and loaded before CHOLMOD asks for those sonames (CHOLMOD's own RUNPATH
# would not see our rpath). Same kernels, one thread: the same results.
#
# The two libraries go to the linker inside -Wl, not as paths CMake sees: a library path in a
# non-system directory makes CMake put that directory in its own build rpath, which the linker
# merges with ours, and `cmake --install` then strips it, so an installed program (the CLI, or
# one built against the installed package) would lose the serial BLAS. CMake leaves the
# -Wl,-rpath below alone.
set(VERTEXFLOW_SERIAL_BLAS_DIR "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/openblas-serial")
if(EXISTS "${VERTEXFLOW_SERIAL_BLAS_DIR}/libblas.so.3" AND EXISTS "${VERTEXFLOW_SERIAL_BLAS_DIR}/liblapack.so.3")
  set(VERTEXFLOW_SERIAL_BLAS
      "-Wl,--push-state,--no-as-needed,${VERTEXFLOW_SERIAL_BLAS_DIR}/liblapack.so.3,${VERTEXFLOW_SERIAL_BLAS_DIR}/libblas.so.3,--pop-state"
      "-Wl,--disable-new-dtags,-rpath,${VERTEXFLOW_SERIAL_BLAS_DIR}")
  set_property(TARGET cholmod::cholmod APPEND PROPERTY INTERFACE_LINK_LIBRARIES ${VERTEXFLOW_SERIAL_BLAS})
endif()
