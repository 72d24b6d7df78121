# What the install and package test scripts share (cmake -P): each step is run and checked with
# a failure that names the step, what went wrong and what to do.

# hiltwin_test_fail(<what> WHY <text...> HINT <text...>): stops the test. The pieces of each
# text are joined, so a long message can be written over several lines. Read from ARGV<n>, not
# parsed as lists, so a ';' in a piece (a command's output) stays as it is.
function(hiltwin_test_fail what)
  set(why "")
  set(hint "")
  set(into why)
  math(EXPR last "${ARGC} - 1")
  foreach(i RANGE 1 ${last})
    if("${ARGV${i}}" STREQUAL "WHY")
      set(into why)
    elseif("${ARGV${i}}" STREQUAL "HINT")
      set(into hint)
    else()
      string(APPEND ${into} "${ARGV${i}}")
    endif()
  endforeach()
  message(FATAL_ERROR "FAILED: ${what}: ${why}\n  what to do: ${hint}")
endfunction()

# hiltwin_test_run(<what> <out_var> [EXIT_CODES <codes...>] [WORKING_DIRECTORY <dir>]
#                  [HINT <text...>] COMMAND <command...>)
# Runs the command with its stdout and stderr merged into <out_var> and its exit code in
# <out_var>_EXIT. An exit code not in EXIT_CODES (default 0) fails the test with the command,
# its output and HINT.
function(hiltwin_test_run what out_var)
  cmake_parse_arguments(ARG "" "WORKING_DIRECTORY" "EXIT_CODES;HINT;COMMAND" ${ARGN})
  if(NOT DEFINED ARG_EXIT_CODES)
    set(ARG_EXIT_CODES 0)
  endif()
  if(NOT ARG_WORKING_DIRECTORY)
    set(ARG_WORKING_DIRECTORY "${WORK_DIR}")
  endif()
  list(JOIN ARG_COMMAND " " command_line)
  message(STATUS "${what}: ${command_line}")
  execute_process(COMMAND ${ARG_COMMAND} WORKING_DIRECTORY "${ARG_WORKING_DIRECTORY}"
                  OUTPUT_VARIABLE output ERROR_VARIABLE output RESULT_VARIABLE code)
  if(NOT code IN_LIST ARG_EXIT_CODES)
    list(JOIN ARG_EXIT_CODES " or " expected)
    hiltwin_test_fail("${what}"
      WHY "exit ${code} (expected ${expected}) from\n    ${command_line}\n"
          "--- its output ---\n${output}--- end of output ---"
      HINT ${ARG_HINT} "read the output above")
  endif()
  set(${out_var} "${output}" PARENT_SCOPE)
  set(${out_var}_EXIT "${code}" PARENT_SCOPE)
endfunction()

# hiltwin_test_require_vars(<names...>): the -D arguments the script needs.
function(hiltwin_test_require_vars)
  foreach(name IN LISTS ARGN)
    if(NOT DEFINED ${name} OR "${${name}}" STREQUAL "")
      hiltwin_test_fail("${CMAKE_SCRIPT_MODE_FILE}" WHY "-D${name}=... is missing"
                        HINT "run it through ctest (tests/integration/install/CMakeLists.txt)")
    endif()
  endforeach()
endfunction()

# hiltwin_test_require_files(<what> <hint> <root> <paths...>): each <root>/<path> exists.
function(hiltwin_test_require_files what hint root)
  foreach(path IN LISTS ARGN)
    if(NOT EXISTS "${root}/${path}")
      hiltwin_test_fail("${what}" WHY "${root}/${path} is missing" HINT "${hint}")
    endif()
  endforeach()
endfunction()

# hiltwin_test_check_verdict(<what> <output> <exit_code>): a run's summary ends in a verdict
# line that agrees with its exit code (README "Exit codes": 0 PASS, 3 FLAGGED).
function(hiltwin_test_check_verdict what output exit_code)
  if(NOT output MATCHES "(^|\n)verdict +([A-Z]+)")
    hiltwin_test_fail("${what}" WHY "no 'verdict' line in the summary:\n${output}"
                      HINT "see FormatSummary in engine/runtime/src/run_report.cpp")
  endif()
  set(verdict "${CMAKE_MATCH_2}")
  if(NOT (exit_code EQUAL 0 AND verdict STREQUAL "PASS") AND
     NOT (exit_code EQUAL 3 AND verdict STREQUAL "FLAGGED"))
    hiltwin_test_fail("${what}" WHY "verdict ${verdict} with exit code ${exit_code}:\n${output}"
                      HINT "expected PASS with 0 or FLAGGED with 3 (README \"Exit codes\")")
  endif()
  message(STATUS "${what}: verdict ${verdict}, exit ${exit_code}")
endfunction()

# hiltwin_test_check_version(<what> <binary>): `<binary> --version` (under EMULATOR when set)
# starts "hiltwin <VERSION> ", the project's version.
function(hiltwin_test_check_version what binary)
  hiltwin_test_run("${what}" out COMMAND ${EMULATOR} "${binary}" --version)
  string(REPLACE "." "\\." version_pattern "${VERSION}")
  if(NOT out MATCHES "^hiltwin ${version_pattern} ")
    hiltwin_test_fail("${what}" WHY "'${out}' does not start 'hiltwin ${VERSION} '"
                      HINT "see cli/version.h and cmake/HiltwinVersion.cmake")
  endif()
  string(STRIP "${out}" out)
  message(STATUS "${what}: ${out}")
endfunction()
