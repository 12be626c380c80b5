# ctest script: the out-of-tree adapter example (examples/out_of_tree_adapter) built against an
# installed partita, as its README and docs/writing_an_adapter.md tell a user to: install the
# build tree into a scratch prefix, configure and build the example with find_package(partita),
# run the Solver contract check on its solver (partita::check_solver_contract, installed), run its
# case and compare the oscillator's displacement at t = 1 s with z_0 cos(omega t). Then the same
# solver as a plugin (liboscillator_plugin.so) in the STOCK installed partita: the plugin carries
# no copy of partita (nm), list/docs/check show it, and runs from the case's plugins: list (the
# copy the example's build puts next to the library), from --plugin with --set, and resumed from
# a restart file give the exact solution. The example is built in a folder of another name, away
# from its sources, as any user's build folder. Last, the plugin's solver coupled with the native
# DEM (lid_on_granules.yaml: a spring-loaded lid on granules) must come to static equilibrium:
# the granules carry the lid's weight plus its spring force, the box the granules' weight plus
# that (check_lid.py, 2 %).
# Arguments: -DBUILD_DIR= -DSOURCE_DIR= -DWORK_DIR= -DGENERATOR= -DPYTHON= -DNM=
set(PROJECT_BUILD ${WORK_DIR}/somewhere/else/osc-build)
include(${CMAKE_CURRENT_LIST_DIR}/install_and_build.cmake)
set(B ${PROJECT_BUILD})
execute_process(COMMAND ${B}/oscillator_partita conformance
                WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(rc OR NOT out MATCHES "conformance: 0 failures")
  message(FATAL_ERROR "the example's solver fails the Solver contract: ${rc} ${out} ${err}")
endif()
execute_process(COMMAND ${B}/oscillator_partita run ${SOURCE_DIR}/oscillator.yaml
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

# --- the plugin in the stock partita ---------------------------------------------------------
set(partita ${WORK_DIR}/prefix/bin/partita)
set(plugin ${B}/liboscillator_plugin.so)
function(run_partita what)  # run_partita(<what it shows> ARGS...): output in `out`, stops on failure
  execute_process(COMMAND ${partita} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  if(rc)
    message(FATAL_ERROR "the stock partita with the plugin failed (${what}): ${rc} ${o} ${e}")
  endif()
  set(out "${o}${e}" PARENT_SCOPE)
endfunction()
# z(t) = 10 mm cos(sqrt(k / 2 kg) t) and the energy 1/2 k z_0^2 in the last row of motion.csv
function(check_oscillator csv k t_end)
  execute_process(COMMAND ${PYTHON} -c
    "import csv,math,sys; r=[float(x) for x in list(csv.reader(open(sys.argv[1])))[-1]]; k=float(sys.argv[2]); T=float(sys.argv[3]); z=0.01*math.cos(math.sqrt(k/2)*r[0]); e=0.5*k*1e-4; print('t =',r[0],'z =',r[1],'exact',z,'energy',r[3],'exact',e); sys.exit(0 if abs(r[0]-T)<1e-12 and abs(r[1]-z)<1e-12 and abs(r[3]-e)<1e-10*e else 1)"
    ${csv} ${k} ${t_end} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  message(STATUS "${csv}: ${o}${e}")
  if(rc)
    message(FATAL_ERROR "the plugin oscillator differs from z_0 cos(omega t): ${o} ${e}")
  endif()
endfunction()

# One copy of partita: the plugin defines none of partita's functions (only the weak copies of
# inline and template code that any user of the headers gets) and refers to them undefined, to
# be resolved from the executable that loads it.
execute_process(COMMAND ${NM} -DC --defined-only ${plugin} RESULT_VARIABLE rc OUTPUT_VARIABLE defined)
string(REGEX MATCHALL "[0-9a-f]+ [TDBR] partita::[^\n]*" own "${defined}")
execute_process(COMMAND ${NM} -DCu ${plugin} OUTPUT_VARIABLE undefined)
if(rc OR own OR NOT undefined MATCHES "U partita::Error::Error")
  message(FATAL_ERROR "the plugin carries its own copy of partita (${rc}): ${own}")
endif()

run_partita("list" list --plugin ${plugin})
if(NOT out MATCHES "oscillator +a mass on a spring along z" OR NOT out MATCHES "tube1d-fluid")
  message(FATAL_ERROR "partita list --plugin does not list the plugin's solver: ${out}")
endif()
run_partita("docs" docs oscillator --plugin ${plugin})
if(NOT out MATCHES "stiffness" OR NOT out MATCHES "kinetic plus spring energy")
  message(FATAL_ERROR "partita docs oscillator --plugin: ${out}")
endif()
# the case names the plugin relative to itself; the example's build copies it next to the library
run_partita("check" check ${B}/oscillator_plugin.yaml)
if(NOT out MATCHES "is valid")
  message(FATAL_ERROR "partita check: ${out}")
endif()
run_partita("run, plugins: in the case" run ${B}/oscillator_plugin.yaml --output ${WORK_DIR}/out_plugin)
check_oscillator(${WORK_DIR}/out_plugin/motion.csv 50 1)
run_partita("resume to t = 2 s" run ${B}/oscillator_plugin.yaml --resume ${WORK_DIR}/out_plugin
            --set time.end=2)
check_oscillator(${WORK_DIR}/out_plugin/motion.csv 50 2)
run_partita("run, --plugin and --set" run ${SOURCE_DIR}/oscillator.yaml --plugin ${plugin}
            --set participants.spring.stiffness=200 --output ${WORK_DIR}/out_cli)
check_oscillator(${WORK_DIR}/out_cli/motion.csv 200 1)

# --- the plugin's solver coupled with the native DEM -----------------------------------------
run_partita("a spring-loaded lid on granules" run ${SOURCE_DIR}/lid_on_granules.yaml --plugin ${plugin}
            --output ${WORK_DIR}/out_lid)
execute_process(COMMAND ${PYTHON} ${SOURCE_DIR}/check_lid.py ${WORK_DIR}/out_lid
                RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
message(STATUS "lid_on_granules.yaml: ${o}${e}")
if(rc)
  message(FATAL_ERROR "the lid on the granules is not in static equilibrium: ${o} ${e}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
