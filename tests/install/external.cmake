# ctest script: the external-program example (examples/external_tube) built against an installed
# partita, as its README tells a user to, then run beside the stock installed partita under
# mpirun: the tube's wall in the program, the fluid in partita. Its coupling.csv and tube.csv
# must be byte for byte those of cases/elastic_tube_1d/iqn-ils.yaml run in one process (the
# same iteration counts: 854 over 100 windows), which the in-tree tube1d-solid computes; and so
# must those of the run stopped at 0.5 s and resumed from its restart file (partita --resume).
# Arguments: -DBUILD_DIR= -DSOURCE_DIR= -DWORK_DIR= -DGENERATOR= -DCASE= -DMPIRUN=
include(${CMAKE_CURRENT_LIST_DIR}/install_and_build.cmake)
set(partita ${WORK_DIR}/prefix/bin/partita)
set(ENV{OMPI_ALLOW_RUN_AS_ROOT} 1)
set(ENV{OMPI_ALLOW_RUN_AS_ROOT_CONFIRM} 1)
set(ENV{PARTITA_LOG_LEVEL} warn)
execute_process(COMMAND ${partita} run ${CASE} -o ${WORK_DIR}/one --threads 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc)
  message(FATAL_ERROR "the tube case in one process failed: ${rc} ${out} ${err}")
endif()
# (with restart files every 10 windows: the program's state in them, compared below)
set(restart --set output.restart.every_windows=10)
# partita (the fluid) beside the program (the wall) under mpirun: PARTITA and PROGRAM are the
# arguments of each after the case; sets rc, out and err
macro(run_with_program)
  cmake_parse_arguments(R "" "" "PARTITA;PROGRAM" ${ARGN})
  execute_process(COMMAND ${MPIRUN} --oversubscribe
                          -n 1 ${partita} run ${SOURCE_DIR}/tube_external.yaml --threads 1
                               --participant fluid ${R_PARTITA} :
                          -n 1 ${WORK_DIR}/build/tube_solid ${SOURCE_DIR}/tube_external.yaml ${R_PROGRAM}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 240)
endmacro()
run_with_program(PARTITA -o ${WORK_DIR}/two ${restart} PROGRAM ${restart})
message(STATUS "${out}")
if(rc OR NOT out MATCHES "tube_solid: finished")
  message(FATAL_ERROR "partita with the external program failed: ${rc} ${out} ${err}")
endif()
# coupling.csv and tube.csv of the run in DIR byte for byte those of the run in one process
function(same_as_one_process dir what)
  foreach(csv coupling.csv tube.csv)
    file(READ ${WORK_DIR}/one/${csv} a)
    file(READ ${dir}/${csv} b)
    if(NOT a STREQUAL b)
      message(FATAL_ERROR "${csv} of ${what} differs from the in-process tube's")
    endif()
  endforeach()
endfunction()
same_as_one_process(${WORK_DIR}/two "the run with the external program")
message(STATUS "coupling.csv and tube.csv are byte for byte those of the run in one process")
# restart: the same run to t = 0.5 s, then resumed from its restart file to the end (1.0 s):
# coupling.csv and tube.csv byte for byte those of the run in one process, and the last restart
# file (the program's part included: the time of its steps and its area) that of the
# uninterrupted run with the external program
set(half ${restart} --set time.end=0.5)
run_with_program(PARTITA -o ${WORK_DIR}/four ${half} PROGRAM ${half})
if(rc OR NOT EXISTS ${WORK_DIR}/four/restart/w000000000050.bin)
  message(FATAL_ERROR "the external program's run to 0.5 s wrote no restart file at window 50: ${rc} ${out} ${err}")
endif()
run_with_program(PARTITA --resume ${WORK_DIR}/four ${restart} PROGRAM ${restart})
message(STATUS "${out}")
if(rc OR NOT out MATCHES "tube_solid: resumed at t = 0.5 s" OR NOT out MATCHES "tube_solid: finished")
  message(FATAL_ERROR "the external program's run did not resume from t = 0.5 s: ${rc} ${out} ${err}")
endif()
same_as_one_process(${WORK_DIR}/four "the resumed run with the external program")
file(SHA256 ${WORK_DIR}/two/restart/w000000000100.bin a)
file(SHA256 ${WORK_DIR}/four/restart/w000000000100.bin b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "the last restart file of the resumed run differs from the uninterrupted one's")
endif()
message(STATUS "resumed at 0.5 s: coupling.csv, tube.csv and the last restart file are those of the uninterrupted run")
# the program as the first process: refused (partita runs the coupling core)
execute_process(COMMAND ${MPIRUN} --oversubscribe
                        -n 1 ${WORK_DIR}/build/tube_solid ${SOURCE_DIR}/tube_external.yaml :
                        -n 1 ${partita} run ${SOURCE_DIR}/tube_external.yaml -o ${WORK_DIR}/three
                             --threads 1 --participant fluid
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
if(NOT rc OR NOT "${out}${err}" MATCHES "start partita first")
  message(FATAL_ERROR "the program as the first process was not refused: ${rc} ${out} ${err}")
endif()
