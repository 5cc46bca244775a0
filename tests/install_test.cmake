# The installed package as another project uses it (ctest -R install):
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DEXAMPLE=<in-tree fourbar_minimal>
#         -P install_test.cmake
# 1. `cmake --install BUILD_DIR --prefix WORK_DIR/prefix`;
# 2. the program is there and runs; every installed header finds the project headers it
#    includes among the installed ones, and no internal header (detail/, yaml-cpp's reader) is
#    installed;
# 3. docs/examples/ configured and built as an outside project against the package alone
#    (find_package(balance_design CONFIG REQUIRED)), and run: it prints what the same example
#    built inside the tree prints, character for character.
cmake_minimum_required(VERSION 3.25)
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR EXAMPLE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install_test.cmake: ${var} not set")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# the program
run(${prefix}/bin/balance-design --version)
if(NOT out MATCHES "^balance-design [0-9]")
  message(FATAL_ERROR "installed balance-design --version printed: ${out}")
endif()
foreach(f lib/cmake/balance_design/balance_designConfig.cmake
          lib/cmake/balance_design/balance_designConfigVersion.cmake
          share/doc/balance-design/README.md share/doc/balance-design/study-format.md
          share/doc/balance-design/examples/CMakeLists.txt
          share/doc/balance-design/examples/fourbar_minimal.cpp
          share/doc/balance-design/studies/paper-fourbar.yaml)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()

# the headers: public ones only, and complete
set(inc ${prefix}/include/balance_design)
file(GLOB_RECURSE headers RELATIVE ${inc} ${inc}/*)
list(LENGTH headers count)
if(count LESS 40)
  message(FATAL_ERROR "only ${count} headers installed in ${inc}")
endif()
foreach(h ${headers})
  if(h MATCHES "/detail/|yaml_reader|load_study_internal|report_support|nlopt_driver|ipopt_driver|integrators")
    message(FATAL_ERROR "internal header installed: ${h}")
  endif()
  file(STRINGS ${inc}/${h} includes REGEX "^#include \"")
  foreach(line ${includes})
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    if(NOT EXISTS ${inc}/${included})
      message(FATAL_ERROR "installed header ${h} includes ${included}, which is not installed")
    endif()
  endforeach()
endforeach()

# the embedding example, an outside project: only the installed package on its prefix path
set(launcher)
find_program(CCACHE ccache)
if(CCACHE)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CCACHE})
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/docs/examples -B ${WORK_DIR}/example
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} ${launcher})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/example)
run(${WORK_DIR}/example/fourbar_minimal)
set(outside "${out}")
run(${EXAMPLE})
if(NOT outside STREQUAL out)
  message(FATAL_ERROR "the example built outside printed\n${outside}\nthe one built in the tree\n${out}")
endif()
if(NOT outside MATCHES "RMS shaking force: [0-9.]+ N, force balanced [0-9.e-]+ N \\(360 samples\\)")
  message(FATAL_ERROR "unexpected output of the example:\n${outside}")
endif()
message(STATUS "installed package ok: ${count} headers; the example printed\n${outside}")
