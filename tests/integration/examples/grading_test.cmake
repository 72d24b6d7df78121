# Examples.GradingTableIsTheMeasuredOne (cmake -P; CMakeLists.txt here passes the -D values):
# examples/grading/README.md's "Measure again" commands, with this build's hiltwin and
# controller libraries: grade.py runs campaigns/relbot_course.toml for tuned_pid, sluggish_p
# and unstable_pi in lockstep, and table.py's table must be the README's, digit for digit, so
# the grades (9, 1 and 1 of 9 scenarios) and every measured value the README and the
# campaign's comments quote are the ones the model gives today.
# In: PYTHON, HILTWIN, CONTROLLER_DIR, SOURCE_DIR, WORK_DIR.
cmake_minimum_required(VERSION 3.25)
foreach(var PYTHON HILTWIN CONTROLLER_DIR SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "grading_test.cmake needs -D${var}=...")
  endif()
endforeach()
set(example "${SOURCE_DIR}/examples/grading")
set(controllers tuned_pid sluggish_p unstable_pi)

function(fail why)
  message(FATAL_ERROR "FAILED: examples/grading: ${why}\n"
          "  what to do: if the model, a controller or a bound changed on purpose, run the "
          "README's \"Measure again\" commands, put the new table in examples/grading/README.md "
          "and update the numbers the comments of campaigns/relbot_course.toml quote")
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
set(tables)
foreach(name ${controllers})
  if(NOT EXISTS "${CONTROLLER_DIR}/${name}.so")
    fail("no ${CONTROLLER_DIR}/${name}.so: build the target hiltwin_grading_controllers")
  endif()
  execute_process(COMMAND "${PYTHON}" "${example}/grade.py" "${HILTWIN}"
                          "${SOURCE_DIR}/campaigns/relbot_course.toml" "${WORK_DIR}/${name}"
                          --controller "lib:${CONTROLLER_DIR}/${name}.so"
                  OUTPUT_FILE "${WORK_DIR}/${name}.jsonl" ERROR_VARIABLE err
                  RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    fail("grade.py for ${name}: exit ${code}\n${err}")
  endif()
  list(APPEND tables "${name}=${WORK_DIR}/${name}.jsonl")
endforeach()
execute_process(COMMAND "${PYTHON}" "${example}/table.py" ${tables}
                OUTPUT_VARIABLE table ERROR_VARIABLE err RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  fail("table.py: exit ${code}\n${err}")
endif()
message(STATUS "measured:\n${table}")
set(grades "| **scenarios passed** | | | 9 of 9 | 1 of 9 | 1 of 9 |")
string(FIND "${table}" "${grades}" at)
if(at EQUAL -1)
  fail("the grades are not pass / fails the step's settling / fails every closed loop "
       "(expected the row '${grades}')")
endif()
file(READ "${example}/README.md" readme)
string(FIND "${readme}" "${table}" at)
if(at EQUAL -1)
  fail("the README's table is not the measured one above")
endif()
