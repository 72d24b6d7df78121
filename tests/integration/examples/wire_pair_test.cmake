# Examples.WirePairClosesTheLoopOnOneWire (cmake -P; CMakeLists.txt here passes the -D values):
# examples/wire_pair/run.sh as its README runs it, with this build's hiltwin and an output
# folder; then both sides' exit codes as printed, both reports, both logs and the wire's
# segment. A real-time pair on a shared machine: a side may be FLAGGED (exit 3), as the HiL
# pair tests allow (tests/integration/cli/hil_cli_test.cpp); everything else must hold.
# In: HILTWIN, SCRIPT, WORK_DIR; TSAN (ON: a ThreadSanitizer build, whose slow processes are
# not judged on tracking accuracy, as HilCli does).
cmake_minimum_required(VERSION 3.25)
foreach(var HILTWIN SCRIPT WORK_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "wire_pair_test.cmake needs -D${var}=...")
  endif()
endforeach()

function(fail why)
  message(FATAL_ERROR "FAILED: examples/wire_pair: ${why}\n"
          "  what to do: compare with examples/wire_pair/README.md (\"What you should see\"); "
          "the same pair by one command: hiltwin hil --duration 2")
endfunction()

# report_value(<out_var> <json> <key...>): a report's value, or a failure naming the key.
function(report_value out_var json side)
  string(JSON value ERROR_VARIABLE error GET "${json}" ${ARGN})
  if(error)
    fail("the ${side} report has no ${ARGN}: ${error}")
  endif()
  set(${out_var} "${value}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
set(out_dir "${WORK_DIR}/out")
message(STATUS "bash ${SCRIPT} ${HILTWIN} ${out_dir}")
execute_process(COMMAND bash "${SCRIPT}" "${HILTWIN}" "${out_dir}" WORKING_DIRECTORY "${WORK_DIR}"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE out)
message(STATUS "exit ${code}:\n${out}")

# What the script prints at the end, and its own exit code: the worse of the two.
if(NOT out MATCHES "wire pair on wire:([A-Za-z0-9_.-]+), output in ")
  fail("no 'wire pair on wire:NAME' line")
endif()
set(wire "${CMAKE_MATCH_1}")
set(codes "")
foreach(side twin controller pair)
  if(NOT out MATCHES "\n${side} exit ([0-9]+)\n")
    fail("no '${side} exit N' line")
  endif()
  set(${side}_code "${CMAKE_MATCH_1}")
  if(NOT ${side}_code MATCHES "^[03]$")
    fail("${side} exit ${${side}_code}: expected 0 (PASS) or 3 (FLAGGED on a busy machine)")
  endif()
endforeach()
if(NOT code EQUAL pair_code)
  fail("run.sh exited ${code} but printed 'pair exit ${pair_code}'")
endif()
if((twin_code EQUAL 3 OR controller_code EQUAL 3) AND NOT pair_code EQUAL 3)
  fail("twin ${twin_code}, controller ${controller_code}: the pair's code must be the worse, 3")
endif()

# The wire's shared memory is gone once both sides ended.
if(EXISTS "/dev/shm/hiltwin-wire-${wire}")
  fail("/dev/shm/hiltwin-wire-${wire} is left behind")
endif()

# The controller ran its 2 s (2000 cycles at 1 kHz) to the end with the twin there throughout;
# the twin was ended by that finish, within its own 4 s.
file(READ "${out_dir}/ecs.json" ecs)
file(READ "${out_dir}/twin.json" twin)
foreach(expect
    "ecs;stop_reason;finished" "ecs;cycles_run;2000" "ecs;peer_absent_cycles;0"
    "ecs;io_errors;0" "ecs;outputs_safe;ON" "ecs;log_rows_written;2000" "ecs;io;wire:${wire}"
    "twin;stop_reason;peer_stopped" "twin;peer_stopped;wire: the ECS finished its run"
    "twin;peer_absent_cycles;0" "twin;io_errors;0" "twin;outputs_safe;ON"
    "twin;io;wire:${wire}")
  list(GET expect 0 side)
  list(GET expect 1 key)
  list(GET expect 2 expected)
  report_value(value "${${side}}" ${side} "${key}")
  if(expected STREQUAL "ON" AND NOT value STREQUAL "ON")
    fail("the ${side} report's ${key} is ${value}, expected true")
  elseif(NOT expected STREQUAL "ON" AND NOT value STREQUAL expected)
    fail("the ${side} report's ${key} is '${value}', expected '${expected}'")
  endif()
endforeach()
report_value(twin_cycles "${twin}" twin cycles_run)
report_value(twin_rows "${twin}" twin log_rows_written)
if(NOT twin_rows EQUAL twin_cycles OR twin_cycles LESS 4000 OR NOT twin_cycles LESS 16000)
  fail("the twin ran ${twin_cycles} cycles and logged ${twin_rows}: expected the same count, "
       "about 8000 (4 kHz while the 2 s controller ran), fewer than its own 16000")
endif()

# A stall of this machine holds either loop while the setpoint moves on (at most 0.625 m/s):
# every position bound below is 3 mm (thesis §7.2) plus what the setpoint travels in the
# longest stall either side saw, as HilCli's bound. Under TSan the slow processes are not
# judged on accuracy.
report_value(twin_stall_ns "${twin}" twin latency_ns max)
report_value(ecs_stall_ns "${ecs}" ecs latency_ns max)
set(stall_ns ${twin_stall_ns})
if(ecs_stall_ns GREATER stall_ns)
  set(stall_ns ${ecs_stall_ns})
endif()
math(EXPR bound_nm "3000000 + ${stall_ns} * 5 / 8")  # nanometres: 0.625 m/s x ns

# A logged position in metres ("0.0361435541890", as the log writes values near the
# setpoint) as whole nanometres, for integer arithmetic.
function(metres_to_nm out text)
  if(NOT text MATCHES "^(-?)0\\.([0-9]+)$")
    fail("a logged position '${text}' is not a plain decimal below 1 m")
  endif()
  set(sign "${CMAKE_MATCH_1}")
  string(SUBSTRING "${CMAKE_MATCH_2}000000000" 0 9 digits)
  string(REGEX REPLACE "^0+" "" digits "${digits}")
  if(digits STREQUAL "")
    set(digits 0)
  endif()
  set(${out} "${sign}${digits}" PARENT_SCOPE)
endfunction()

# The controller's log ends on the built-in setpoint at t = 1.999 s (the same every run:
# a function of the cycle, 31,059,709 nm), and the twin drove its wheels there: its last
# logged wheel positions within the bound of it.
file(STRINGS "${out_dir}/ecs.csv" ecs_rows)
list(GET ecs_rows 0 header)
if(NOT header MATCHES "^time_s,setpoint_left_m,setpoint_right_m,")
  fail("ecs.csv starts '${header}'")
endif()
list(GET ecs_rows -1 last)
string(REPLACE "," ";" cells "${last}")
list(GET cells 0 t)
list(GET cells 1 setpoint)
if(NOT t EQUAL 1.999 OR NOT setpoint GREATER 0.0310597088 OR NOT setpoint LESS 0.0310597089)
  fail("the controller's last row is '${last}': expected t = 1.999 s at setpoint 0.03106 m")
endif()
file(STRINGS "${out_dir}/twin.csv" twin_rows)
list(GET twin_rows 0 header)
if(NOT header MATCHES "^time_s,duty_left,duty_right,wheel_left_m,wheel_right_m,")
  fail("twin.csv starts '${header}'")
endif()
list(GET twin_rows -1 last)
string(REPLACE "," ";" cells "${last}")
list(GET cells 3 left)
list(GET cells 4 right)
if(NOT TSAN)
  foreach(wheel left right)
    metres_to_nm(wheel_nm "${${wheel}}")
    math(EXPR off_nm "${wheel_nm} - 31059709")
    if(off_nm LESS 0)
      math(EXPR off_nm "-${off_nm}")
    endif()
    if(off_nm GREATER bound_nm)
      fail("the twin's last row is '${last}': its ${wheel} wheel is ${off_nm} nm from the "
           "setpoint, above the ${bound_nm} nm a ${stall_ns} ns stall allows")
    endif()
  endforeach()
endif()

# Tracking (thesis §7.2), within the same bound.
if(NOT TSAN)
  foreach(wheel left right)
    report_value(error_m "${ecs}" ecs tracking max_abs_error_m ${wheel})
    if(NOT error_m LESS "${bound_nm}e-9")
      fail("the ${wheel} wheel's tracking error is ${error_m} m, above ${bound_nm} nm")
    endif()
  endforeach()
endif()
message(STATUS "examples/wire_pair: twin exit ${twin_code}, controller exit ${controller_code}, "
               "${twin_cycles} twin cycles, wire:${wire} removed")
