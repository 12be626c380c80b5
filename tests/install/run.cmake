# ctest script: install the build tree into a scratch prefix, then configure, build and run the
# consumer project against it. Arguments: -DBUILD_DIR= -DSOURCE_DIR= -DWORK_DIR= -DGENERATOR=
include(${CMAKE_CURRENT_LIST_DIR}/install_and_build.cmake)
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "consumer: ${out}")
if(rc OR NOT out MATCHES "solvers")
  message(FATAL_ERROR "the consumer did not run: ${rc} ${out}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
