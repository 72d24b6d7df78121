# The doc-block checker (doc_blocks.cmake) must fail, naming the line at fault, on pages that
# are wrong in each way it guards against; cmake -P, -DSOURCE_DIR=... -DWORK_DIR=... -DDOC=...
# (the real page, from which one wrong copy is made). Each case runs doc_blocks_check.cmake
# as a process and expects a nonzero exit and "<copy>:<line>:" in its message.
cmake_minimum_required(VERSION 3.25)
include("${CMAKE_CURRENT_LIST_DIR}/test_steps.cmake")
hiltwin_test_require_vars(SOURCE_DIR WORK_DIR DOC)
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}/run")

# expect_failure(<case> <page text> <line> <words> [RUN]): the checker refuses the page, naming
# <line> of it, and its message contains <words>. RUN: with a RUN_DIR, so commands run.
function(expect_failure case text line words)
  set(page "${WORK_DIR}/${case}.md")
  file(WRITE "${page}" "${text}")
  set(run_arg "")
  if(ARGN STREQUAL "RUN")
    set(run_arg "-DRUN_DIR=${WORK_DIR}/run")
  endif()
  execute_process(COMMAND "${CMAKE_COMMAND}" "-DDOC=${page}" "-DSOURCE_DIR=${SOURCE_DIR}"
                          ${run_arg} -P "${CMAKE_CURRENT_LIST_DIR}/doc_blocks_check.cmake"
                  OUTPUT_VARIABLE out ERROR_VARIABLE out RESULT_VARIABLE code)
  string(REGEX REPLACE "[ \n]+" " " out "${out}")  # CMake wraps a long message at spaces
  string(FIND "${out}" "${page}:${line}:" named)
  string(FIND "${out}" "${words}" said)
  if(code EQUAL 0 OR named EQUAL -1 OR said EQUAL -1)
    hiltwin_test_fail("the checker on ${case}"
      WHY "exit ${code}, expected a failure naming ${page}:${line}: and saying '${words}':\n"
          "${out}"
      HINT "see tests/integration/install/doc_blocks.cmake")
  endif()
  message(STATUS "${case}: refused at line ${line}, as it should")
endfunction()

# 1. The real page with one character of the C file changed in its copy.
file(READ "${DOC}" page)
set(original "#define KP 600.0")
string(FIND "${page}" "${original}" at)
if(at EQUAL -1)
  hiltwin_test_fail("${DOC}" WHY "it does not show '${original}' (the example's my_pd.c)"
                    HINT "update the self-check's wrong copy to a line the page shows")
endif()
string(SUBSTRING "${page}" 0 ${at} before)
string(REGEX MATCHALL "\n" newlines "${before}")
list(LENGTH newlines line)
math(EXPR line "${line} + 1")
string(REPLACE "${original}" "#define KP 601.0" wrong "${page}")
expect_failure(wrong_file_copy "${wrong}" ${line} "differs from that file at its line")

# 2. A file block whose tag names no file.
expect_failure(no_such_file "text\n<!-- file: examples/nope.c -->\n```c\nint x;\n```\n" 2
               "not a file of")
# 3. A tag not followed by its block.
expect_failure(tag_without_block "<!-- run -->\n\n```sh\ntrue\n```\n" 1 "not followed by")
# 4. A run tag on a block of another language.
expect_failure(run_not_sh "<!-- run -->\n```bash\ntrue\n```\n" 1 "not followed by a ```sh")
# 5. A misspelt tag.
expect_failure(misspelt_tag "<!-- run: exit 0 and 3 -->\n```sh\ntrue\n```\n" 1
               "not a tag this test knows")
# 6. A command that fails, on its own line of the block.
expect_failure(failing_command "# page\n<!-- run -->\n```sh\ntrue\n\nfalse\n```\n" 6
               "`false` exited 1 (the block's tag expects 0)" RUN)
# 7. An exit code the tag does not list.
expect_failure(unlisted_code "<!-- run: exit 0 or 3 -->\n```sh\nexit 4\n```\n" 3
               "exited 4 (the block's tag expects 0 or 3)" RUN)
# 8. An output block that is not what the command printed, at its second line.
expect_failure(wrong_output
  "<!-- run -->\n```sh\nprintf 'one\\ntwo\\n'\n```\n\n<!-- output -->\n```text\none\nthree\n```\n"
  9 "the page: three" RUN)
# 9. A digest that is not the file's, though digests are compared as HASH.
file(WRITE "${WORK_DIR}/run/lib.so" "bytes")
string(CONCAT page "<!-- run -->\n```sh\necho \"$PWD/lib.so, sha256 00ff\"\n```\n"
       "<!-- output -->\n```text\nDIR/lib.so, sha256 00ff\n```\n")
expect_failure(wrong_digest "${page}" 7 "the file's is" RUN)
# 10. A page that ends inside a block.
expect_failure(unclosed_block "<!-- file: README.md -->\n```\ntext\n" 1 "ends inside a block")

# And the control: the same kind of page, right, passes.
set(page "${WORK_DIR}/right.md")
file(WRITE "${page}"
  "<!-- run -->\n```sh\n"
  "echo \"wire:hil-1 $PWD/lib.so, sha256 $(sha256sum lib.so | cut -c1-64)\"\n```\n"
  "<!-- output -->\n```text\nwire:hil-42 /home/student/lib.so, sha256 ab12\n```\n")
execute_process(COMMAND "${CMAKE_COMMAND}" "-DDOC=${page}" "-DSOURCE_DIR=${SOURCE_DIR}"
                        "-DRUN_DIR=${WORK_DIR}/run"
                        -P "${CMAKE_CURRENT_LIST_DIR}/doc_blocks_check.cmake"
                OUTPUT_VARIABLE out ERROR_VARIABLE out RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  hiltwin_test_fail("the checker on a right page" WHY "exit ${code}:\n${out}"
                    HINT "see tests/integration/install/doc_blocks.cmake")
endif()
message(STATUS "a right page passes")
