# hiltwin_add_version_library(<target>): a static library whose one symbol,
# hiltwin::app::kVersionText (cli/version.h), is the text of `hiltwin --version`.
# Its source is written at every build by cmake/WriteVersionSource.cmake from `git describe`,
# so a new commit or a dirty tree shows without reconfiguring.
function(hiltwin_add_version_library target)
  set(source "${CMAKE_CURRENT_BINARY_DIR}/hiltwin_version.cpp")
  # A target, not a command with OUTPUT: it must run at every build, and BYPRODUCTS lets the
  # library depend on the file it writes (rewritten only when the text changes).
  add_custom_target(${target}_source
    COMMAND "${CMAKE_COMMAND}" -DPROJECT_VERSION=${PROJECT_VERSION}
            "-DSOURCE_DIR=${PROJECT_SOURCE_DIR}" "-DOUTPUT=${source}"
            -P "${PROJECT_SOURCE_DIR}/cmake/WriteVersionSource.cmake"
    BYPRODUCTS "${source}"
    COMMENT "hiltwin --version: git describe"
    VERBATIM)
  add_library(${target} STATIC "${source}")
  add_dependencies(${target} ${target}_source)
  target_include_directories(${target} PUBLIC "${CMAKE_CURRENT_SOURCE_DIR}")
  hiltwin_target_warnings(${target})
endfunction()
