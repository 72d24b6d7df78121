# Examples.PlantMapFmuMatchesTheAnalyticMsd (cmake -P; CMakeLists.txt here passes the -D values):
# examples/plant_map_fmu/README.md's command, run from the source folder as the README runs it
# from the repository's top, with this build's msd.fmu and hiltwin; then the exit code, the
# summary, the report and the log checked against the closed-form answer.
# In: HILTWIN, FMU, SOURCE_DIR, WORK_DIR; EMULATOR when cross-compiling.
cmake_minimum_required(VERSION 3.25)
foreach(var HILTWIN FMU SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "plant_map_fmu_test.cmake needs -D${var}=...")
  endif()
endforeach()

function(fail why)
  message(FATAL_ERROR "FAILED: examples/plant_map_fmu: ${why}\n"
          "  what to do: compare with examples/plant_map_fmu/README.md (\"What you should see\"); "
          "the map is examples/plant_map_fmu/msd_map.toml, the FMU tests/fmus/msd_model.c")
endfunction()

if(NOT EXISTS "${FMU}")
  fail("no ${FMU}: build it with cmake --build <build> --target hiltwin_test_fmu_msd_fmu")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
set(log "${WORK_DIR}/msd.csv")
set(report "${WORK_DIR}/msd.json")
set(map examples/plant_map_fmu/msd_map.toml)
set(input examples/plant_map_fmu/force_step.csv)

# The README's command; only the FMU's and the outputs' folders differ.
set(command ${EMULATOR} "${HILTWIN}" run --plant "fmu:${FMU}" --plant-map ${map}
    --input ${input} --clock virtual --rate 2000 --duration 3 --log "${log}"
    --report "${report}")
list(JOIN command " " command_line)
message(STATUS "in ${SOURCE_DIR}: ${command_line}")
execute_process(COMMAND ${command} WORKING_DIRECTORY "${SOURCE_DIR}" RESULT_VARIABLE code
                OUTPUT_VARIABLE out ERROR_VARIABLE out)
message(STATUS "exit ${code}:\n${out}")
if(NOT code EQUAL 0)
  fail("exit ${code}, expected 0 (PASS)")
endif()
string(REGEX REPLACE "([][+.*?()^$|\\])" "\\\\\\1" fmu_regex "${FMU}")
foreach(line
    "plant fmu:${fmu_regex} twin at 2000 Hz for 3.000 s \\(6000 cycles\\), io mock, input ${input}, virtual clock"
    "cycles +6000 of 6000 at 2000 Hz \\(virtual clock\\), stop: finished"
    "log +[^\n]*msd.csv: 6000 rows written, 0 dropped"
    "verdict +PASS")
  if(NOT out MATCHES "${line}")
    fail("the summary has no line matching '${line}'")
  endif()
endforeach()

# The report: the plant, its map and the run's account.
file(READ "${report}" json)
foreach(pair "verdict=PASS" "stop_reason=finished" "cycles_run=6000" "log_rows_written=6000"
             "log_rows_dropped=0" "plant=fmu:${FMU}" "plant kind=FMI 2.0 co-simulation"
             "plant map=${map}" "modelName=MassSpringDamper" "input=${input}")
  string(FIND "${pair}" "=" at)
  string(SUBSTRING "${pair}" 0 ${at} key)
  math(EXPR at "${at} + 1")
  string(SUBSTRING "${pair}" ${at} -1 expected)
  string(JSON value ERROR_VARIABLE error GET "${json}" "${key}")
  if(error OR NOT value STREQUAL expected)
    fail("the report's \"${key}\" is '${value}' ${error}, expected '${expected}'")
  endif()
endforeach()

# The log: time_s, the plant's ports (F in, x and v out), the encoder, then the timing columns.
file(STRINGS "${log}" rows)
list(LENGTH rows count)
if(NOT count EQUAL 6001)
  fail("${log} has ${count} lines, expected a header and 6000 rows")
endif()
list(GET rows 0 header)
if(NOT header MATCHES "^time_s,F,x,v,enc1,cycle,")
  fail("${log} starts '${header}', expected 'time_s,F,x,v,enc1,cycle,...'")
endif()

# The force, F = 10 N x the duty that channel 1's PWM reader measured: 0 up to t = 1 s, then
# 0.8 as the PWM carries it (1638/2048), 7.998046875 N, from the row of t = 1.0005 s on (one
# twin period after the step: that row's step is the first the push acts over). So 2000 rows of
# 0 N and 4000 of the push.
set(zero 0)
set(push 0)
set(other "")
foreach(row IN LISTS rows)
  if(row MATCHES "^[0-9.e+-]+,([^,]*),")
    if(CMAKE_MATCH_1 STREQUAL "0")
      math(EXPR zero "${zero} + 1")
    elseif(CMAKE_MATCH_1 STREQUAL "7.998046875")
      math(EXPR push "${push} + 1")
    else()
      set(other "${row}")
    endif()
  endif()
endforeach()
if(NOT zero EQUAL 2000 OR NOT push EQUAL 4000 OR other)
  fail("F is 0 N in ${zero} rows and 7.998046875 N in ${push}, expected 2000 and 4000 "
       "(another value: '${other}')")
endif()

# x(t) in closed form (m = 1 kg, k = 40 N/m, c = 0.8 N s/m; sigma = c/2m = 0.4 /s,
# wd = sqrt(k/m - sigma^2) = 6.3119 rad/s): from x(0) = 0.1 m at rest,
# x(t) = 0.1 e^(-sigma t) (cos wd t + sigma/wd sin wd t) up to t = 1 s; from there the same
# free response from x(1) and v(1) around the new rest position F/k = 0.19995 m. The FMU steps
# it exactly (tests/fmus/msd_model.c), so the log agrees to rounding: within 1e-9 m here.
# enc1 = floor(5000 x) - floor(5000 * 0.1): counted from where the mass started.
# Each check: row (= cycle + 1), t [s], F [N], x low, x high [m], enc1.
foreach(spec
    "995 0.4975 0 -0.0819475028 -0.0819475008 -910"          # the first trough, t = pi/wd
    "2000 1 0 0.0671263181 0.0671263201 -165"                 # the last row before the push
    "2001 1.0005 7.998046875 0.0671208866 0.0671208886 -165"  # the push's first row
    "3000 1.5 7.998046875 0.3088093816 0.3088093836 1044"     # the overshoot past 0.19995 m
    "6000 3 7.998046875 0.1401006130 0.1401006150 200")       # the end of the run
  separate_arguments(spec)
  list(GET spec 0 index)
  list(GET spec 1 t)
  list(GET spec 2 f)
  list(GET spec 3 x_low)
  list(GET spec 4 x_high)
  list(GET spec 5 enc)
  list(GET rows ${index} row)
  string(REPLACE "," ";" cells "${row}")
  list(GET cells 0 got_t)
  list(GET cells 1 got_f)
  list(GET cells 2 got_x)
  list(GET cells 4 got_enc)
  if(NOT got_t EQUAL t OR NOT got_f EQUAL f OR NOT got_enc EQUAL enc
     OR NOT got_x GREATER x_low OR NOT got_x LESS x_high)
    fail("row ${index} is '${row}', expected t = ${t} s, F = ${f} N, x in "
         "[${x_low}, ${x_high}] m, enc1 = ${enc}")
  endif()
endforeach()
message(STATUS "examples/plant_map_fmu: exit 0, PASS, 6000 rows; F, x and enc1 as the closed "
               "form says")
