# Checks the tagged code blocks of one Markdown page (doc_blocks.cmake), cmake -P:
#   -DDOC=<page> -DSOURCE_DIR=<repository> [-DMIN_BLOCKS=<n>] [-DRUN_DIR=<folder to run in>]
# Without RUN_DIR only the file blocks are compared (no build needed); with it the run blocks
# run in order in RUN_DIR with the environment this process has. MIN_BLOCKS: fewer tagged
# blocks fail (a page that lost its tags would otherwise check nothing).
cmake_minimum_required(VERSION 3.25)
include("${CMAKE_CURRENT_LIST_DIR}/test_steps.cmake")
include("${CMAKE_CURRENT_LIST_DIR}/doc_blocks.cmake")
hiltwin_test_require_vars(DOC SOURCE_DIR)
hiltwin_doc_blocks("${DOC}")
if(DEFINED MIN_BLOCKS AND doc_blocks_checked LESS MIN_BLOCKS)
  hiltwin_test_fail("${DOC}" WHY "${doc_blocks_checked} tagged blocks, fewer than ${MIN_BLOCKS}"
                    HINT "tag the blocks the test keeps true (doc_blocks.cmake), or lower "
                         "MIN_BLOCKS where the test is added")
endif()
message(STATUS "${DOC}: ${doc_blocks_checked} tagged blocks checked")
