# The code blocks of a Markdown page kept true by a test (cmake -P; include test_steps.cmake
# first). An HTML comment on the line before a fenced block says what the block is:
#   <!-- file: PATH -->           the block equals SOURCE_DIR/PATH byte for byte
#   <!-- run -->                  an ```sh block whose lines are commands, run one by one in
#   <!-- run: exit 0 or 3 -->     RUN_DIR with `sh -c` (blank lines and # comments skipped);
#                                 each must exit 0, or with one of the codes the tag lists
#   <!-- output -->               a ```text block: what the last command run printed (stdout
#                                 and stderr), after hiltwin_doc_normalize on both sides
# Any other block is prose. A mistake (a block that differs, a command that fails, a tag not
# followed by its block) fails with the page's path and the line of the block at fault, so a
# doc edit that breaks a block names the line to fix. Without RUN_DIR the run and output
# blocks are parsed but not run.

# hiltwin_doc_normalize(<var>): what may differ from one machine and run to the next becomes a
# fixed word, in the page's block and in the real output alike: the wire's name (its process
# id), absolute paths (where the student's folder is) and SHA-256 digests (the compiler's
# bytes; hiltwin_doc_check_hashes checks the real ones).
function(hiltwin_doc_normalize var)
  set(text "${${var}}")
  string(REGEX REPLACE "wire:hil-[0-9]+" "wire:hil-PID" text "${text}")
  string(REGEX REPLACE "(^|[ (\n])/[^ \n,;)]*/" "\\1DIR/" text "${text}")
  string(REGEX REPLACE "sha256 [0-9a-f]+" "sha256 HASH" text "${text}")
  set(${var} "${text}" PARENT_SCOPE)
endfunction()

# hiltwin_doc_check_hashes(<where> <output>): every "PATH, sha256 HEX" the output names is the
# SHA-256 of that file, so normalizing the digest away hides no wrong one.
function(hiltwin_doc_check_hashes where output)
  string(REGEX MATCHALL "(/[^ \n,]+), sha256 ([0-9a-f]+)" pairs "${output}")
  foreach(pair IN LISTS pairs)
    string(REGEX MATCH "^(/[^ \n,]+), sha256 ([0-9a-f]+)$" _ "${pair}")
    set(path "${CMAKE_MATCH_1}")
    set(shown "${CMAKE_MATCH_2}")
    set(actual "(no such file)")
    if(EXISTS "${path}")
      file(SHA256 "${path}" actual)
    endif()
    if(NOT shown STREQUAL actual)
      hiltwin_test_fail("${where}" WHY "the output gives ${path} the SHA-256 ${shown}, but the "
                        "file's is ${actual}"
                        HINT "see ControllerLine in cli/runs/src/hil_report.cpp")
    endif()
  endforeach()
endfunction()

# hiltwin_doc_first_difference(<a> <b> <line_var> <a_var> <b_var>): the 0-based line at which
# the texts first differ and that line of each ("(end)" past the last line).
function(hiltwin_doc_first_difference a b line_var a_var b_var)
  set(index 0)
  while(TRUE)
    foreach(side a b)
      string(FIND "${${side}}" "\n" nl)
      if(nl EQUAL -1)
        set(${side}_line "${${side}}")
        set(${side} "")
        if(${side}_line STREQUAL "")
          set(${side}_line "(end)")
        endif()
      else()
        string(SUBSTRING "${${side}}" 0 ${nl} ${side}_line)
        math(EXPR after "${nl} + 1")
        string(SUBSTRING "${${side}}" ${after} -1 ${side})
      endif()
    endforeach()
    if(NOT a_line STREQUAL b_line OR (a STREQUAL "" AND b STREQUAL ""))
      break()
    endif()
    math(EXPR index "${index} + 1")
  endwhile()
  set(${line_var} ${index} PARENT_SCOPE)
  set(${a_var} "${a_line}" PARENT_SCOPE)
  set(${b_var} "${b_line}" PARENT_SCOPE)
endfunction()

# hiltwin_doc_check_file(<doc> <body_line> <block> <path>): the block, whose first line is
# <body_line> of the page, equals SOURCE_DIR/<path>.
function(hiltwin_doc_check_file doc body_line block path)
  set(file "${SOURCE_DIR}/${path}")
  if(NOT EXISTS "${file}")
    math(EXPR tag_line "${body_line} - 2")
    hiltwin_test_fail("${doc}:${tag_line}" WHY "the block is tagged file: ${path}, which is not "
                      "a file of ${SOURCE_DIR}" HINT "correct the path in the tag")
  endif()
  file(READ "${file}" content)
  if(block STREQUAL content)
    return()
  endif()
  hiltwin_doc_first_difference("${block}" "${content}" index doc_text file_text)
  math(EXPR line "${body_line} + ${index}")
  math(EXPR file_line "${index} + 1")
  hiltwin_test_fail("${doc}:${line}"
    WHY "the block tagged file: ${path} differs from that file at its line ${file_line}:\n"
        "    the page: ${doc_text}\n    the file: ${file_text}"
    HINT "copy the file into the block (or the block into the file: the page shows the file "
         "whole, byte for byte)")
endfunction()

# hiltwin_doc_run_block(<doc> <body_line> <block> <exit_codes>): runs each command in RUN_DIR;
# the last one's output is left in doc_last_output and doc_last_command (PARENT_SCOPE).
function(hiltwin_doc_run_block doc body_line block exit_codes)
  set(line ${body_line})
  set(output "")
  set(command_text "")
  while(NOT block STREQUAL "")
    string(FIND "${block}" "\n" nl)
    string(SUBSTRING "${block}" 0 ${nl} command)
    math(EXPR after "${nl} + 1")
    string(SUBSTRING "${block}" ${after} -1 block)
    string(STRIP "${command}" stripped)
    if(NOT stripped STREQUAL "" AND NOT stripped MATCHES "^#")
      message(STATUS "${doc}:${line}: ${command}")
      string(TIMESTAMP start_s "%s")
      execute_process(COMMAND sh -c "${command}" WORKING_DIRECTORY "${RUN_DIR}"
                      OUTPUT_VARIABLE output ERROR_VARIABLE output RESULT_VARIABLE code)
      string(TIMESTAMP end_s "%s")
      math(EXPR took_s "${end_s} - ${start_s}")
      if(NOT code IN_LIST exit_codes)
        list(JOIN exit_codes " or " expected)
        hiltwin_test_fail("${doc}:${line}"
          WHY "`${command}` exited ${code} (the block's tag expects ${expected}), in "
              "${RUN_DIR}:\n--- its output ---\n${output}--- end of output ---"
          HINT "make the command work as the page says, or correct the page")
      endif()
      message(STATUS "  exit ${code} after ${took_s} s")
      set(command_text "${command}")
    endif()
    math(EXPR line "${line} + 1")
  endwhile()
  set(doc_last_output "${output}" PARENT_SCOPE)
  set(doc_last_command "${command_text}" PARENT_SCOPE)
endfunction()

# hiltwin_doc_check_output(<doc> <body_line> <block> <output> <command>)
function(hiltwin_doc_check_output doc body_line block output command)
  if(command STREQUAL "")
    math(EXPR tag_line "${body_line} - 2")
    hiltwin_test_fail("${doc}:${tag_line}" WHY "an output block with no command run before it"
                      HINT "put a block tagged <!-- run --> before it")
  endif()
  hiltwin_doc_check_hashes("${doc}:${body_line}" "${output}")
  hiltwin_doc_normalize(block)
  hiltwin_doc_normalize(output)
  if(block STREQUAL output)
    return()
  endif()
  hiltwin_doc_first_difference("${block}" "${output}" index doc_text real_text)
  math(EXPR line "${body_line} + ${index}")
  hiltwin_test_fail("${doc}:${line}"
    WHY "the page shows what `${command}` prints, but it printed another line (paths, digests "
        "and wire names compared as DIR, HASH and PID):\n    the page: ${doc_text}\n"
        "    printed:  ${real_text}\n--- all it printed ---\n${output}--- end ---"
    HINT "paste the real output into the block, or make the code print what the page says")
endfunction()

# hiltwin_doc_tag(<doc> <line_number> <line> <kind_var> <arg_var>): the kind of block the tag
# on this line announces (file, run, output, or empty for none) and its argument.
function(hiltwin_doc_tag doc number line kind_var arg_var)
  set(kind "")
  set(arg "")
  if(line MATCHES "^<!-- file: ([^ ]+) -->$")
    set(kind file)
    set(arg "${CMAKE_MATCH_1}")
  elseif(line MATCHES "^<!-- run -->$")
    set(kind run)
    set(arg 0)
  elseif(line MATCHES "^<!-- run: exit ([0-9]+( or [0-9]+)*) -->$")
    set(kind run)
    string(REPLACE " or " ";" arg "${CMAKE_MATCH_1}")
  elseif(line MATCHES "^<!-- output -->$")
    set(kind output)
  elseif(line MATCHES "^<!-- (file|run|output)")
    hiltwin_test_fail("${doc}:${number}" WHY "'${line}' is not a tag this test knows"
      HINT "write <!-- file: PATH -->, <!-- run -->, <!-- run: exit 0 or 3 --> or "
           "<!-- output --> (tests/integration/install/doc_blocks.cmake)")
  endif()
  set(${kind_var} "${kind}" PARENT_SCOPE)
  set(${arg_var} "${arg}" PARENT_SCOPE)
endfunction()

# hiltwin_doc_blocks(<doc>): checks every tagged block of the page, in order; runs the run
# blocks and checks the output blocks when RUN_DIR is set. Sets doc_blocks_checked to the
# number of tagged blocks (PARENT_SCOPE), so a caller can tell a page that lost its tags.
function(hiltwin_doc_blocks doc)
  file(READ "${doc}" rest)
  set(number 0)
  set(tag "")        # the kind of block the last tag announced, until its fence opens
  set(tag_arg "")
  set(tag_line 0)
  set(fence "")      # inside a block: the kind it was tagged with ("prose" for none)
  set(checked 0)
  set(doc_last_output "")
  set(doc_last_command "")
  while(NOT rest STREQUAL "")
    string(FIND "${rest}" "\n" nl)
    if(nl EQUAL -1)
      set(line "${rest}")
      set(rest "")
    else()
      string(SUBSTRING "${rest}" 0 ${nl} line)
      math(EXPR after "${nl} + 1")
      string(SUBSTRING "${rest}" ${after} -1 rest)
    endif()
    math(EXPR number "${number} + 1")
    if(NOT fence STREQUAL "")
      if(NOT line STREQUAL "```")
        string(APPEND block "${line}\n")
        continue()
      endif()
      if(fence STREQUAL "file")
        hiltwin_doc_check_file("${doc}" ${body_line} "${block}" "${fence_arg}")
      elseif(fence STREQUAL "run" AND DEFINED RUN_DIR AND NOT RUN_DIR STREQUAL "")
        hiltwin_doc_run_block("${doc}" ${body_line} "${block}" "${fence_arg}")
      elseif(fence STREQUAL "output" AND DEFINED RUN_DIR AND NOT RUN_DIR STREQUAL "")
        hiltwin_doc_check_output("${doc}" ${body_line} "${block}" "${doc_last_output}"
                                 "${doc_last_command}")
      endif()
      set(fence "")
      continue()
    endif()
    if(NOT tag STREQUAL "")
      set(wanted_fence "```")
      if(tag STREQUAL "run")
        set(wanted_fence "```sh")
      elseif(tag STREQUAL "output")
        set(wanted_fence "```text")
      endif()
      if(NOT line MATCHES "^```" OR (NOT tag STREQUAL "file" AND NOT line STREQUAL wanted_fence))
        hiltwin_test_fail("${doc}:${tag_line}" WHY "the tag is not followed by a ${wanted_fence} "
                          "block on the next line (line ${number} is '${line}')"
                          HINT "put the block right under its tag, or remove the tag")
      endif()
      set(fence "${tag}")
      set(fence_arg "${tag_arg}")
      math(EXPR body_line "${number} + 1")
      set(block "")
      set(tag "")
      math(EXPR checked "${checked} + 1")
      continue()
    endif()
    if(line MATCHES "^```")
      set(fence prose)
      set(block "")
      set(tag_line ${number})
      continue()
    endif()
    hiltwin_doc_tag("${doc}" ${number} "${line}" tag tag_arg)
    set(tag_line ${number})
  endwhile()
  if(NOT fence STREQUAL "" OR NOT tag STREQUAL "")
    hiltwin_test_fail("${doc}:${tag_line}" WHY "the page ends inside a block, or a tag has no block"
                      HINT "close the block with a line of ``` alone")
  endif()
  set(doc_blocks_checked ${checked} PARENT_SCOPE)
endfunction()
