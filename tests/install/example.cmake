# ctest script: the out-of-tree adapter example (examples/out_of_tree_adapter) built against an
# installed partita, as its README and docs/writing_an_adapter.md tell a user to: install the
# build tree into a scratch prefix, configure and build the example with find_package(partita),
# run the Solver contract check on its solver (partita::check_solver_contract, installed), run its
# case and compare the oscillator's displacement at t = 1 s with z_0 cos(omega t).
# Arguments: -DBUILD_DIR= -DSOURCE_DIR= -DWORK_DIR= -DGENERATOR= -DPYTHON=
include(${CMAKE_CURRENT_LIST_DIR}/install_and_build.cmake)
execute_process(COMMAND ${WORK_DIR}/build/oscillator_partita conformance
                WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(rc OR NOT out MATCHES "conformance: 0 failures")
  message(FATAL_ERROR "the example's solver fails the Solver contract: ${rc} ${out} ${err}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/oscillator_partita run ${SOURCE_DIR}/oscillator.yaml
                        ${WORK_DIR}/out
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc)
  message(FATAL_ERROR "the example's case did not run: ${rc} ${out} ${err}")
endif()
# z(1 s) = 10 mm cos(5 rad/s * 1 s), the exact solution the adapter integrates
execute_process(COMMAND ${PYTHON} -c
  "import csv,math,sys; rows=list(csv.reader(open(sys.argv[1]))); t,z=float(rows[-1][0]),float(rows[-1][1]); e=0.01*math.cos(5*t); print('t =',t,'z =',z,'exact',e); sys.exit(0 if abs(t-1)<1e-12 and abs(z-e)<1e-12 else 1)"
  ${WORK_DIR}/out/motion.csv RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(rc)
  message(FATAL_ERROR "the oscillator's displacement differs from z_0 cos(omega t): ${out} ${err}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
