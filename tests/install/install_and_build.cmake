# Included by the install tests: install the build tree BUILD_DIR into WORK_DIR/prefix, then
# configure and build the project SOURCE_DIR against it (find_package(partita)) in PROJECT_BUILD
# (default WORK_DIR/build) with GENERATOR. Stops with FATAL_ERROR at the first step that fails.
if(NOT PROJECT_BUILD)
  set(PROJECT_BUILD ${WORK_DIR}/build)
endif()
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${PROJECT_BUILD} -G ${GENERATOR}
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring ${SOURCE_DIR} with find_package(partita) failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${PROJECT_BUILD} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building ${SOURCE_DIR} against the installed partita failed: ${rc}")
endif()
