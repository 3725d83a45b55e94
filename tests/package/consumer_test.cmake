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

# The installed Python module imports from the prefix with no library path set
# (its run path is relative) and finds the installed libg2p, not this build's.
file(GLOB_RECURSE py_modules ${prefix}/lib/g2p.cpython-*.so)
if(G2P_EXPECT_PYTHON AND NOT py_modules)
  message(FATAL_ERROR "cmake --install put no Python module under ${prefix}/lib")
endif()
if(py_modules)
  list(GET py_modules 0 py_module)
  get_filename_component(py_dir ${py_module} DIRECTORY)
  set(ENV{LD_LIBRARY_PATH} "")
  set(ENV{PYTHONPATH} ${py_dir})
  # (No semicolons in the program: CMake would split the argument there.)
  run(/usr/bin/python3 -c "import g2p\nprint(g2p.__file__)\nprint(g2p.load_model('${G2P_SAMPLE_MODEL}').num_faces)")
  message(STATUS "the installed Python module:\n${last_output}")
  if(NOT last_output MATCHES "^${py_dir}/g2p\\.cpython" OR NOT last_output MATCHES "\n104\n")
    message(FATAL_ERROR "the installed Python module printed unexpected output:\n${last_output}")
  endif()
  if(NOT EXISTS ${py_dir}/g2p_dask_batch.py)
    message(FATAL_ERROR "g2p_dask_batch.py was not installed beside the Python module")
  endif()
  execute_process(COMMAND ldd ${py_module} OUTPUT_VARIABLE ldd_out)
  if(NOT ldd_out MATCHES "libg2p\\.so\\.0 => ${prefix}/")
    message(FATAL_ERROR "the installed Python module does not load the installed libg2p:\n${ldd_out}")
  endif()
endif()
