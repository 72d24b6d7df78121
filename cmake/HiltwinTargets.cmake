# Shared target set-up: one place for the warning set, sanitizers, modules and tests.

include(${CMAKE_CURRENT_LIST_DIR}/HiltwinTiers.cmake)

# Warning set applied to every target of ours, tests and benchmarks included.
function(hiltwin_target_warnings target)
  # The C++-only ones apply to C++ sources only, so a C source (a check of a C library's
  # header, say) builds without "valid for C++ but not for C" noise.
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow
    "$<$<COMPILE_LANGUAGE:CXX>:-Wnon-virtual-dtor;-Wold-style-cast;-Woverloaded-virtual>"
    -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough -Wcast-align -Wmisleading-indentation)
  if(HILTWIN_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# Compile time (docs/testing.md has the figures). A 2-core machine builds this tree up to five
# times in CI, and much of a translation unit's time goes to the same heavy headers (the
# standard library, Eigen, GoogleTest, nlohmann-json, spdlog, CLI11) and the same inline code
# compiled again and again. Unity builds: a target's sources are compiled HILTWIN_UNITY_BATCH at
# a time as one unit, so each batch parses the headers and emits their inline functions once.
# A file that cannot share a unit sets SKIP_UNITY_BUILD_INCLUSION in its folder's
# CMakeLists.txt, with the reason. The tests also share one precompiled header
# (hiltwin_test_pch below).
option(HILTWIN_UNITY_BUILD "Compile each target's sources in batches (unity build)" ON)
set(HILTWIN_UNITY_BATCH 8 CACHE STRING "Sources per unity-build unit")
set(HILTWIN_TEST_LABELS "" CACHE STRING
    "Build only the test executables with a test of one of these labels (empty: all)")
set(HILTWIN_TEST_SKIP_LABELS "" CACHE STRING
    "Build no test executable whose every test has one of these labels")
function(hiltwin_target_build_speed target)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ${HILTWIN_UNITY_BUILD}
                        UNITY_BUILD_BATCH_SIZE ${HILTWIN_UNITY_BATCH})
endfunction()

# The tests' own code is compiled for debugging (-Og) with line tables (-g1), not for speed: a
# test body is hundreds of expanded assertion macros that -O2 spends most of a test's compile
# time on (a unity unit of hiltwin_unit_io: 13.0 s at -O2, 6.7 s at -Og), and full debug
# information costs another fifth (a unit of the app tests: 15.8 s at -Og -g, 12.4 s at
# -Og -g1). What a test measures runs in the libraries, which keep the build type's
# optimisation and debug information; a failing assertion and a sanitizer's backtrace still name
# file and line. To step through a test's own locals in a debugger, configure with
# -DHILTWIN_TEST_OPTIMIZATION="-O0;-g". A test's results do not change: the code is the same,
# and no level contracts floating point (-ffp-contract=off, CMakeLists.txt) or uses x87.
set(HILTWIN_TEST_OPTIMIZATION "-Og;-g1" CACHE STRING
    "Optimisation and debug information of the tests' own code (a list; empty: the build type's)")
function(hiltwin_test_target_flags target)
  hiltwin_target_warnings(${target})
  hiltwin_target_build_speed(${target})
  if(HILTWIN_TEST_OPTIMIZATION)
    target_compile_options(${target} PRIVATE ${HILTWIN_TEST_OPTIMIZATION})
  endif()
  if(CMAKE_CROSSCOMPILING_EMULATOR)
    # Under an emulator (arm64 under qemu, which translates every instruction) the few tests
    # that repeat one computation a million times run a tenth of it, with the same assertions:
    # what arm64 can break (widths, atomics, alignment) shows in the first iterations as in the
    # millionth, and the native stages run them in full (docs/testing.md).
    target_compile_definitions(${target} PRIVATE HILTWIN_UNDER_EMULATOR=1)
  endif()
endfunction()

# One precompiled header for every test executable (REUSE_FROM): the headers nearly every test
# parses, GoogleTest, gmock, nlohmann-json and the standard library's most used, compiled once
# per tree instead of once per unit (measured in the normal tree: the tests' compile 423 ->
# 333 CPU-s, the header's own 10 s included; at -g it was 274 MB and made a unit slower, which
# is why it came only after the tests moved to -g1).
# GCC takes a precompiled header only when the unit's code-generation flags and the macros it
# uses match, so it is built with the tests' own flags (hiltwin_test_target_flags) and links
# what defines GoogleTest's macros; an executable with other such flags (one that undefines
# NDEBUG) passes OWN_FLAGS to hiltwin_add_gtest and parses the headers itself.
function(hiltwin_test_pch_target)
  if(TARGET hiltwin_test_pch)
    return()
  endif()
  file(WRITE "${CMAKE_BINARY_DIR}/hiltwin_test_pch.cpp"
       "// The object of the tests' shared precompiled header (cmake/HiltwinTargets.cmake).\n")
  add_library(hiltwin_test_pch OBJECT "${CMAKE_BINARY_DIR}/hiltwin_test_pch.cpp")
  target_link_libraries(hiltwin_test_pch PRIVATE GTest::gtest GTest::gmock
                        nlohmann_json::nlohmann_json)
  target_compile_features(hiltwin_test_pch PRIVATE cxx_std_20)
  hiltwin_test_target_flags(hiltwin_test_pch)
  target_precompile_headers(hiltwin_test_pch PRIVATE
    <gtest/gtest.h> <gmock/gmock.h> <nlohmann/json.hpp> <algorithm> <atomic> <chrono> <cstdint>
    <filesystem> <fstream> <memory> <sstream> <string> <thread> <vector>)
endfunction()

# Sanitizers are global so that every object, including GoogleTest's main, agrees.
# HILTWIN_FUZZ: every object gets libFuzzer's coverage instrumentation (fuzzer-no-link) with
# ASan + UBSan, so a fuzz target sees the edges of the parsers it calls; only the fuzz targets
# link libFuzzer itself (-fsanitize=fuzzer, fuzz/CMakeLists.txt), as it brings its own main.
macro(hiltwin_apply_sanitizers)
  if(HILTWIN_FUZZ)
    if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang" OR NOT CMAKE_C_COMPILER_ID STREQUAL "Clang")
      message(FATAL_ERROR "HILTWIN_FUZZ needs clang's libFuzzer, but the compilers are "
                          "${CMAKE_C_COMPILER_ID}/${CMAKE_CXX_COMPILER_ID}: configure a fresh build "
                          "folder with CC=clang CXX=clang++ (scripts/fuzz.sh does; Debian: "
                          "apt-get install clang libclang-rt-14-dev)")
    endif()
    if(HILTWIN_SANITIZE OR HILTWIN_TSAN)
      message(FATAL_ERROR "HILTWIN_FUZZ already builds with ASan + UBSan: drop HILTWIN_SANITIZE "
                          "and HILTWIN_TSAN")
    endif()
    add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                        -fno-sanitize-recover=all)
    add_link_options(-fsanitize=address,undefined)
    add_compile_definitions(HILTWIN_UNDER_SANITIZER=1 HILTWIN_FUZZING=1)
  elseif(HILTWIN_SANITIZE)
    add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
    add_link_options(-fsanitize=address,undefined)
    add_compile_definitions(HILTWIN_UNDER_SANITIZER=1)
  elseif(HILTWIN_TSAN)
    add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
    add_link_options(-fsanitize=thread)
    add_compile_definitions(HILTWIN_UNDER_SANITIZER=1)
  endif()
endmacro()

# hiltwin_add_module(<name> [DEPS <targets...>] [PRIVATE_DEPS <targets...>])
# One static library per module folder: sources src/*.cpp, public headers
# include/hiltwin/<name>/, alias hiltwin::<name>. Its dependencies obey the tiers
# (HiltwinTiers.cmake).
# Installable (cmake/HiltwinInstall.cmake): exported under the same name hiltwin::<name>, the
# headers come from the source tree only while building (the install rules add
# <prefix>/include), and users are asked for C++20, which the headers need (std::span).
function(hiltwin_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS" ${ARGN})
  hiltwin_check_tier(${name} ${ARG_DEPS} ${ARG_PRIVATE_DEPS})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp"
       "${CMAKE_CURRENT_SOURCE_DIR}/src/*.c")
  set(target hiltwin_${name})
  set(public_include "$<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>")
  if(sources)
    add_library(${target} STATIC ${sources})
    target_include_directories(${target} PUBLIC "${public_include}"
                               PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}/src")
    target_link_libraries(${target} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    target_compile_features(${target} PUBLIC cxx_std_20)
    hiltwin_target_warnings(${target})
    hiltwin_target_build_speed(${target})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE "${public_include}")
    target_link_libraries(${target} INTERFACE ${ARG_DEPS})
    target_compile_features(${target} INTERFACE cxx_std_20)
  endif()
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  add_library(hiltwin::${name} ALIAS ${target})
endfunction()

# Under TSan a report fails the test at once (and in every hiltwin process it starts, which
# inherit the variable); tests/tsan.supp names the uninstrumented libraries whose reports are
# noise. Every test's ENVIRONMENT property, ours and plain add_test ones alike.
set(HILTWIN_TSAN_TEST_ENVIRONMENT)
if(HILTWIN_TSAN)
  set(HILTWIN_TSAN_TEST_ENVIRONMENT ENVIRONMENT "TSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/\
tests/tsan.supp:halt_on_error=1:second_deadlock_stack=1")
endif()

# hiltwin_labels_wanted(<out_var> "<labels some test has>" "<labels every test has>"): whether
# this build keeps such tests: HILTWIN_TEST_LABELS (empty: all) names a label some test has, and
# HILTWIN_TEST_SKIP_LABELS names none of the labels every test has.
function(hiltwin_labels_wanted out_var some every)
  set(wanted TRUE)
  if(NOT HILTWIN_TEST_LABELS STREQUAL "")
    set(wanted FALSE)
    foreach(label IN LISTS some)
      if(label IN_LIST HILTWIN_TEST_LABELS)
        set(wanted TRUE)
      endif()
    endforeach()
  endif()
  foreach(label IN LISTS every)
    if(label IN_LIST HILTWIN_TEST_SKIP_LABELS)
      set(wanted FALSE)
    endif()
  endforeach()
  set(${out_var} ${wanted} PARENT_SCOPE)
endfunction()

# hiltwin_add_gtest(<name> SOURCES <files...> LIBS <targets...> LABELS <labels...>
#                   [RT_TESTS <regex>] [CONCURRENCY_TESTS <regex>]
#                   [SLOW_TESTS <regex>=<seconds>...] [SERIAL_TESTS <regex>] [TIMEOUT s]
#                   [RESOURCE_LOCK <names...>] [OWN_FLAGS])
# A GoogleTest executable whose tests CTest discovers one by one, with labels
# (unit, integration, rt, concurrency, long, soak) so suites can be chosen with `ctest -L`;
# docs/testing.md says which stage runs which label.
# OWN_FLAGS: the executable changes code-generation flags or macros the shared precompiled
# header depends on (say -UNDEBUG), so it does not use it (hiltwin_test_pch_target).
# RESOURCE_LOCK: names CTest never runs two holders of at once (`lttng`: the one session
# daemon, started and stopped by whichever test needs it; `tracefs`: the kernel's tracer). Each
# name is a label too, so a stage that has no such thing leaves those tests out by name
# (`-LE lttng`: the arm64 suite under qemu, whose emulated processes cannot reach the host's
# session daemon).
# RT_TESTS: the tests (Suite.Name) that depend on the wall clock also get the label `rt`, so
# `ctest -L rt` selects exactly the tests a noisy machine can disturb.
# CONCURRENCY_TESTS: the tests that race threads or processes (lock-free queues, the logger,
# the wire, telemetry, session threads, two-process pairs) also get the label `concurrency`:
# the ThreadSanitizer stage runs exactly these (".*": every test of the executable).
# SERIAL_TESTS: the tests (Suite.Name) that CTest runs with no other test beside them
# (RUN_SERIAL): a test whose assertion is about everything the machine runs, as the trace test
# that names its own competitor the top culprit of the misses (other tests' compilers, cpack,
# real-time threads and browsers came out as culprits under `ctest -j`).
# SLOW_TESTS: the tests that take ten seconds or more in some stage, each with its seconds in
# the stage where it is slowest (measured; CTest's COST), so that `ctest -j` starts the longest
# first: a fresh clone has no CTestCostData.txt, and CTest otherwise starts them wherever their
# number falls and ends on one core running them alone (the quick tier's RTL runs: 86 s, 68 s).
# HILTWIN_TEST_LABELS (a CMake list; empty: all): only the executables that hold a test with one
# of these labels are built and known to CTest. A stage that runs one label (the TSan stage:
# concurrency; arm64: unit) then compiles no test it would not run.
# HILTWIN_TEST_SKIP_LABELS (a CMake list): executables whose every test has one of these labels
# are left out the same way (the sanitizer stage: long, which no stage but the opt-in one runs).
# gtest_discover_tests flattens a list given to PROPERTIES, so the labels and locks are set by
# a CTest include file that runs after discovery, over the discovered list.
# Cross-compiled (arm64), discovery runs the test binary at test time, under the emulator,
# not at build time: the build then needs no emulator at all.
function(hiltwin_add_gtest name)
  cmake_parse_arguments(ARG "OWN_FLAGS" "TIMEOUT;RT_TESTS;CONCURRENCY_TESTS;SERIAL_TESTS"
                        "SOURCES;LIBS;LABELS;RESOURCE_LOCK;SLOW_TESTS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  if(CMAKE_CROSSCOMPILING_EMULATOR)
    # Under qemu every instruction is translated: the same test takes several times as long.
    math(EXPR ARG_TIMEOUT "${ARG_TIMEOUT} * ${HILTWIN_EMULATOR_TIME_FACTOR}")
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  hiltwin_test_target_flags(${name})
  if(NOT ARG_OWN_FLAGS)
    hiltwin_test_pch_target()
    target_precompile_headers(${name} REUSE_FROM hiltwin_test_pch)
  endif()
  set(labels ${ARG_LABELS} ${ARG_RESOURCE_LOCK})
  set(possible_labels ${labels})
  if(ARG_RT_TESTS)
    list(APPEND possible_labels rt)
  endif()
  if(ARG_CONCURRENCY_TESTS)
    list(APPEND possible_labels concurrency)
  endif()
  hiltwin_labels_wanted(wanted "${possible_labels}" "${labels}")
  if(NOT wanted)
    # Still a target, so its folder can set its properties, but neither built by default nor
    # known to CTest.
    set_target_properties(${name} PROPERTIES EXCLUDE_FROM_ALL ON)
    return()
  endif()
  set(extra_properties ${HILTWIN_TSAN_TEST_ENVIRONMENT})
  set(discovery_mode POST_BUILD)
  if(CMAKE_CROSSCOMPILING)
    set(discovery_mode PRE_TEST)
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_TIMEOUT 120
    DISCOVERY_MODE ${discovery_mode}
    TEST_LIST ${name}_TESTS
    # A test that skips (GTEST_SKIP: no daemon, no privilege) shows as skipped, not passed.
    PROPERTIES TIMEOUT ${ARG_TIMEOUT} ${extra_properties}
               SKIP_REGULAR_EXPRESSION "\\[  SKIPPED \\]"
    EXTRA_ARGS --gtest_color=no)
  set(script "${CMAKE_CURRENT_BINARY_DIR}/${name}_labels.cmake")
  # One string built with APPEND: a list here would lose the ';' inside the label list.
  set(content "# Generated by hiltwin_add_gtest: labels and locks of every discovered test.\n")
  string(APPEND content "foreach(test IN LISTS ${name}_TESTS)\n  set(labels \"${labels}\")\n")
  foreach(regex_label IN ITEMS "RT_TESTS;rt" "CONCURRENCY_TESTS;concurrency")
    list(GET regex_label 0 argument)
    list(GET regex_label 1 label)
    if(ARG_${argument})
      string(APPEND content
        "  if(test MATCHES [=[${ARG_${argument}}]=])\n"
        "    list(APPEND labels ${label})\n"
        "  endif()\n")
    endif()
  endforeach()
  string(APPEND content "  set_tests_properties(\"\${test}\" PROPERTIES LABELS \"\${labels}\"")
  if(ARG_RESOURCE_LOCK)
    string(APPEND content " RESOURCE_LOCK \"${ARG_RESOURCE_LOCK}\"")
  endif()
  string(APPEND content ")\n")
  if(ARG_SERIAL_TESTS)
    string(APPEND content
      "  if(test MATCHES [=[${ARG_SERIAL_TESTS}]=])\n"
      "    set_tests_properties(\"\${test}\" PROPERTIES RUN_SERIAL TRUE)\n"
      "  endif()\n")
  endif()
  foreach(slow IN LISTS ARG_SLOW_TESTS)
    if(NOT slow MATCHES "^(.+)=([0-9]+)$")
      message(FATAL_ERROR "hiltwin_add_gtest(${name}): SLOW_TESTS entry '${slow}' is not "
                          "<regex>=<seconds>")
    endif()
    string(APPEND content
      "  if(test MATCHES [=[${CMAKE_MATCH_1}]=])\n"
      "    set_tests_properties(\"\${test}\" PROPERTIES COST ${CMAKE_MATCH_2})\n"
      "  endif()\n")
  endforeach()
  string(APPEND content "endforeach()\n")
  file(WRITE "${script}" "${content}")
  # Appended after gtest_discover_tests's own include file, so it runs after discovery.
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${script}")
endfunction()

# hiltwin_test_paths(<test> NAME=<path> ...): the files a test reads or runs (the hiltwin binary,
# a helper program, a TOML file of the source tree), as macros NAME that expand to an absolute
# path found at run time: the path relative to the test program's own folder, resolved against
# /proc/self/exe (tests/fakes/test_paths.h). A path spelled into the compile command would put
# the clone's folder into the unit's preprocessed text, where ccache keys on it, and a second
# clone's test units would all miss the cache (docs/testing.md). <path> is an absolute path or
# $<TARGET_FILE:target>; an empty one stays "" (the test skips what it names). The macros are
# defined when the top folder is done: a helper program's folder may come after the test's.
function(hiltwin_test_paths test)
  foreach(pair IN LISTS ARGN)
    if(NOT pair MATCHES "^([A-Z0-9_]+)=(.*)$")
      message(FATAL_ERROR "hiltwin_test_paths(${test}): '${pair}' is not NAME=PATH")
    endif()
    cmake_language(EVAL CODE "cmake_language(DEFER DIRECTORY [[${PROJECT_SOURCE_DIR}]] CALL
                   hiltwin_define_test_path [[${test}]] [[${CMAKE_MATCH_1}]] [[${CMAKE_MATCH_2}]])")
  endforeach()
  target_link_libraries(${test} PRIVATE hiltwin::test_fakes)
endfunction()

function(hiltwin_define_test_path test name path)
  if(path STREQUAL "")
    target_compile_definitions(${test} PRIVATE "${name}=\"\"")
    return()
  endif()
  get_target_property(test_dir ${test} BINARY_DIR)
  if(path MATCHES "^\\$<TARGET_FILE:([^>]+)>$")
    set(target ${CMAKE_MATCH_1})
    get_target_property(target_dir ${target} RUNTIME_OUTPUT_DIRECTORY)
    if(NOT target_dir)
      get_target_property(target_dir ${target} BINARY_DIR)
    endif()
    file(RELATIVE_PATH relative "${test_dir}" "${target_dir}/_")
    string(REGEX REPLACE "_$" "$<TARGET_FILE_NAME:${target}>" relative "${relative}")
  elseif(IS_ABSOLUTE "${path}")
    file(RELATIVE_PATH relative "${test_dir}" "${path}")
  else()
    message(FATAL_ERROR "hiltwin_test_paths(${test}): ${name}=${path} is neither an absolute "
                        "path nor $<TARGET_FILE:target>")
  endif()
  target_compile_definitions(${test} PRIVATE
                             "${name}=::hiltwin::test::BesideTest(\"${relative}\")")
endfunction()
