# The man page and the bash completion script of a program, made at build time by the built
# program itself, so they always match its command line:
#   hiltwin_man_page(<target>): target hiltwin_man_page, ${PROJECT_BINARY_DIR}/<target>.1 from
#     help2man over `<target> --help` and `--version`, plus a COMMANDS section holding
#     `<target> <command> --help` for every command `<target> completion bash` lists
#   hiltwin_bash_completion(<target>): target hiltwin_bash_completion,
#     ${PROJECT_BINARY_DIR}/<target>.bash from `<target> completion bash --output`
# Both belong to ALL. Cross-compiled, the program runs under CMAKE_CROSSCOMPILING_EMULATOR
# (qemu-aarch64 for arm64: a few seconds); without an emulator they are not defined, and the
# install rules and tests that use them say so or leave them out.
#
# This file has two roles: include()d, it defines the two functions; run with `cmake -P` by
# the man page's rule, it writes the page (the part after return()).

if(NOT CMAKE_SCRIPT_MODE_FILE)

# Sets <out> to the command that runs <target> on this machine (a list: the emulator first
# when cross-compiling). Leaves <out> empty, saying so, when the program cannot run here to
# make <what>.
function(_hiltwin_program_runner out target what)
  set(runner "$<TARGET_FILE:${target}>")
  if(CMAKE_CROSSCOMPILING)
    if(CMAKE_CROSSCOMPILING_EMULATOR)
      set(runner ${CMAKE_CROSSCOMPILING_EMULATOR} "$<TARGET_FILE:${target}>")
    else()
      message(STATUS "${target}: no CMAKE_CROSSCOMPILING_EMULATOR to run it, so no ${what} "
                     "(install qemu-user-static: scripts/setup.sh --cross arm64)")
      set(runner "")
    endif()
  endif()
  set(${out} "${runner}" PARENT_SCOPE)
endfunction()

function(hiltwin_bash_completion target)
  _hiltwin_program_runner(runner ${target} "${target}.bash")
  if(NOT runner)
    return()
  endif()
  set(output "${PROJECT_BINARY_DIR}/${target}.bash")
  add_custom_command(OUTPUT "${output}"
    COMMAND ${runner} completion bash --output "${output}"
    DEPENDS ${target}
    COMMENT "${target}.bash: bash completion from the command line"
    VERBATIM)
  add_custom_target(hiltwin_bash_completion ALL DEPENDS "${output}")
endfunction()

function(hiltwin_man_page target)
  _hiltwin_program_runner(runner ${target} "${target}.1")
  if(NOT runner)
    return()
  endif()
  find_program(HILTWIN_HELP2MAN help2man)
  if(NOT HILTWIN_HELP2MAN)
    message(WARNING "help2man not found: no man page ${target}.1 (Debian: apt-get install "
                    "help2man; scripts/setup.sh installs it)")
    return()
  endif()
  set(output "${PROJECT_BINARY_DIR}/${target}.1")
  # The emulator and the program travel as one -D list: $<SEMICOLON> keeps the custom command
  # from splitting it into separate arguments.
  string(REPLACE ";" "$<SEMICOLON>" program "${runner}")
  add_custom_command(OUTPUT "${output}"
    COMMAND "${CMAKE_COMMAND}" "-DPROGRAM=${program}" "-DHELP2MAN=${HILTWIN_HELP2MAN}"
            "-DOUTPUT=${output}" "-DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/man_page"
            -P "${CMAKE_CURRENT_FUNCTION_LIST_FILE}"
    DEPENDS ${target} "${CMAKE_CURRENT_FUNCTION_LIST_FILE}"
    COMMENT "${target}.1: man page from --help (help2man)"
    VERBATIM)
  add_custom_target(hiltwin_man_page ALL DEPENDS "${output}")
endfunction()

return()
endif()

# ---- cmake -P: PROGRAM (list: [emulator...] program), HELP2MAN, OUTPUT, WORK_DIR ----

# Runs PROGRAM with ARGN and sets <out> to its stdout; a failure stops the build, naming the
# command and what it said.
function(run_program out)
  execute_process(COMMAND ${PROGRAM} ${ARGN} OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr
                  RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    list(JOIN PROGRAM " " shown)
    message(FATAL_ERROR "man page: '${shown} ${ARGN}' failed (${result}): ${stderr}")
  endif()
  set(${out} "${stdout}" PARENT_SCOPE)
endfunction()

# The text as roff that prints it verbatim: backslashes and dashes escaped, and a line that
# starts with a control character ('.' or ') guarded by \&.
function(roff_literal out text)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REPLACE "-" "\\-" text "${text}")
  string(REGEX REPLACE "(^|\n)([.'])" "\\1\\\\&\\2" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# The commands, from the script's "# Commands: A B ..." line (cli/bash_completion.h):
# the program's own list, so a new command gets its section without touching this file.
run_program(script completion bash)
if(NOT script MATCHES "\n# Commands: ([^\n]+)")
  message(FATAL_ERROR "man page: no '# Commands:' line in the output of 'completion bash'; "
                      "its header is what lists the commands (bash_completion.h)")
endif()
string(REPLACE " " ";" commands "${CMAKE_MATCH_1}")

list(GET PROGRAM -1 program_path)
get_filename_component(name "${program_path}" NAME)
string(CONCAT sections "[COMMANDS]\nEach command has its own options; "
       "\\fB${name} \\fIcommand\\fB \\-\\-help\\fR prints them, as below.\n")
foreach(command IN LISTS commands)
  run_program(help ${command} --help)
  roff_literal(help "${help}")
  string(APPEND sections ".SS \"${name} ${command}\"\n.nf\n${help}.fi\n")
endforeach()
# The full version text goes in a section of its own: in the page's footer, where help2man
# puts it by default, a long `git describe` runs into the date on an 80-column terminal.
run_program(version --version)
string(STRIP "${version}" version)
roff_literal(version_roff "${version}")
string(REPLACE " " "\\ " version_roff "${version_roff}")  # unbreakable: one piece on the page
string(APPEND sections "[VERSION]\nThis page documents \\fB${version_roff}\\fR "
                       "(\\fB${name} \\-\\-version\\fR).\n")
string(REGEX MATCH "^[^ ]+ [^ ]+" short_version "${version}")  # "hiltwin 0.1.0"
file(MAKE_DIRECTORY "${WORK_DIR}")
file(WRITE "${WORK_DIR}/${name}.h2m" "${sections}")

# NAME: the first sentence of the description ("hiltwin: a real-time ... twins.").
run_program(help --help)
set(name_option "")
if(help MATCHES "^[^\n:]+: ([^\n]+)\\.\n")
  set(name_option --name "${CMAKE_MATCH_1}")
endif()
# help2man runs its program argument through the shell: quote every word of PROGRAM.
set(shell_command "")
foreach(word IN LISTS PROGRAM)
  string(REPLACE "'" "'\\''" word "${word}")
  string(APPEND shell_command "'${word}' ")
endforeach()
string(STRIP "${shell_command}" shell_command)
execute_process(COMMAND "${HELP2MAN}" --no-info --section 1 ${name_option}
                        --source "${short_version}" --include "${WORK_DIR}/${name}.h2m"
                        --output "${OUTPUT}" "${shell_command}"
                RESULT_VARIABLE result ERROR_VARIABLE stderr)
if(NOT result EQUAL 0)
  file(REMOVE "${OUTPUT}")
  message(FATAL_ERROR "man page: help2man failed (${result}): ${stderr}")
endif()
