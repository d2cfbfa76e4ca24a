# ctest Package/consumer (cmake -P): installs the build BUILD_DIR into WORK_DIR/prefix, configures and
# builds the project SOURCE_DIR (tests/consumer) against that prefix only, runs it on CASE; with PYTHON,
# also imports the installed Python module from the prefix.
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix}
                OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
set(extra)
if(LAUNCHER)
  list(APPEND extra -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
                        -DCMAKE_PREFIX_PATH=${prefix} -DEXPECTED_PREFIX=${prefix} -DCMAKE_CXX_COMPILER=${CXX} ${extra}
                        -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE
                COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND ${WORK_DIR}/build/consumer ${CASE} COMMAND_ERROR_IS_FATAL ANY)
if(PYTHON)
  file(GLOB_RECURSE modules ${prefix}/*/hybridmesh*.so)
  list(LENGTH modules n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "expected one installed Python module under ${prefix}, found: ${modules}")
  endif()
  get_filename_component(pydir ${modules} DIRECTORY)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${pydir} ${PYTHON} -c
                          "import hybridmesh; assert hybridmesh.__file__.startswith('${prefix}/'), hybridmesh.__file__; print('installed', hybridmesh.__file__)"
                  COMMAND_ERROR_IS_FATAL ANY)
endif()
