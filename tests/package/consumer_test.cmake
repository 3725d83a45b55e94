# Installs the built libg2p into a scratch prefix, then configures, builds and
# runs a consumer project that uses find_package(g2p REQUIRED) and pkg-config.
foreach(var G2P_BUILD_DIR G2P_CONSUMER_SOURCE G2P_WORK_DIR G2P_SAMPLE_MODEL)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "consumer_test.cmake needs -D${var}=...")
  endif()
endforeach()

set(prefix ${G2P_WORK_DIR}/prefix)
set(build ${G2P_WORK_DIR}/consumer-build)
file(REMOVE_RECURSE ${prefix} ${build})

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

run(${CMAKE_COMMAND} --install ${G2P_BUILD_DIR} --prefix ${prefix})
run(${CMAKE_COMMAND} -S ${G2P_CONSUMER_SOURCE} -B ${build} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${build})
run(${build}/consumer ${G2P_SAMPLE_MODEL})
message(STATUS "consumer output:\n${last_output}")
if(NOT last_output MATCHES "faces 104" OR NOT last_output MATCHES "steel_head")
  message(FATAL_ERROR "consumer printed unexpected output")
endif()

# The installed g2p runs from the prefix with no library path set (its run
# path is relative) and turns the sample model into assets.
if(EXISTS ${prefix}/bin/g2p)
  set(ENV{LD_LIBRARY_PATH} "")
  run(${prefix}/bin/g2p run ${G2P_SAMPLE_MODEL} -o ${G2P_WORK_DIR}/installed-run --overwrite -q --format mjcf)
  if(NOT last_output MATCHES "2 parts")
    message(FATAL_ERROR "the installed g2p printed unexpected output:\n${last_output}")
  endif()
  if(NOT EXISTS ${G2P_WORK_DIR}/installed-run/hammer.xml)
    message(FATAL_ERROR "the installed g2p wrote no hammer.xml")
  endif()
endif()

# A version the package cannot satisfy must be refused (SameMajorVersion).
execute_process(COMMAND ${CMAKE_COMMAND} -S ${G2P_CONSUMER_SOURCE} -B ${build}-v9 -DCMAKE_PREFIX_PATH=${prefix}
                        -DCONSUMER_G2P_VERSION=9.0
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
file(REMOVE_RECURSE ${build}-v9)
if(rc EQUAL 0)
  message(FATAL_ERROR "find_package(g2p 9.0) succeeded against a 0.x package")
endif()

# pkg-config finds the relocated install tree and its flags compile and link.
find_program(PKG_CONFIG pkg-config)
if(PKG_CONFIG)
  file(GLOB_RECURSE pc_files ${prefix}/*/g2p.pc)
  list(GET pc_files 0 pc)
  get_filename_component(pc_dir ${pc} DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} ${pc_dir})
  run(${PKG_CONFIG} --cflags --libs g2p)
  string(STRIP "${last_output}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  run(c++ -std=c++17 ${G2P_CONSUMER_SOURCE}/main.cpp -o ${G2P_WORK_DIR}/pc-consumer ${flags}
      -Wl,-rpath,${prefix}/lib)
endif()
