# Shared target set-up: one place for the warning set, sanitizers, modules and tests.

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
# include/hiltwin/<name>/, alias hiltwin::<name>.
function(hiltwin_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp"
       "${CMAKE_CURRENT_SOURCE_DIR}/src/*.c")
  if(sources)
    add_library(hiltwin_${name} STATIC ${sources})
    target_include_directories(hiltwin_${name} PUBLIC "${CMAKE_CURRENT_SOURCE_DIR}/include"
                               PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}/src")
    target_link_libraries(hiltwin_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    hiltwin_target_warnings(hiltwin_${name})
  else()
    add_library(hiltwin_${name} INTERFACE)
    target_include_directories(hiltwin_${name} INTERFACE "${CMAKE_CURRENT_SOURCE_DIR}/include")
    target_link_libraries(hiltwin_${name} INTERFACE ${ARG_DEPS})
  endif()
  add_library(hiltwin::${name} ALIAS hiltwin_${name})
endfunction()

# hiltwin_add_gtest(<name> SOURCES <files...> LIBS <targets...> LABELS <labels...>
#                   [RT_TESTS <regex>] [TIMEOUT s] [RESOURCE_LOCK name])
# A GoogleTest executable whose tests CTest discovers one by one, with labels
# (unit, integration, rt, soak) so suites can be chosen with `ctest -L`.
# RESOURCE_LOCK: a name CTest never runs two holders of at once (`lttng`: the one session
# daemon, started and stopped by whichever test needs it; `tracefs`: the kernel's tracer).
# RT_TESTS: the tests (Suite.Name) that depend on the wall clock also get the label `rt`, so
# `ctest -L rt` selects exactly the tests a noisy machine can disturb. gtest_discover_tests
# flattens a list given to PROPERTIES, so the second label is set by a CTest include file that
# runs after discovery, over the discovered list.
function(hiltwin_add_gtest name)
  cmake_parse_arguments(ARG "" "TIMEOUT;RT_TESTS;RESOURCE_LOCK" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  hiltwin_target_warnings(${name})
  set(extra_properties)
  if(ARG_RESOURCE_LOCK)
    set(extra_properties RESOURCE_LOCK ${ARG_RESOURCE_LOCK})
  endif()
  if(HILTWIN_TSAN)
    # A report fails the test at once (and in every hiltwin process it starts, which inherit
    # the variable); tests/tsan.supp names the uninstrumented libraries whose reports are noise.
    list(APPEND extra_properties ENVIRONMENT
         "TSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tests/tsan.supp:halt_on_error=1:second_deadlock_stack=1")
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_TIMEOUT 60
    TEST_LIST ${name}_TESTS
    # A test that skips (GTEST_SKIP: no daemon, no privilege) shows as skipped, not passed.
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT} ${extra_properties}
               SKIP_REGULAR_EXPRESSION "\\[  SKIPPED \\]"
    EXTRA_ARGS --gtest_color=no)
  if(ARG_RT_TESTS)
    set(rt_labels ${ARG_LABELS} rt)
    set(script "${CMAKE_CURRENT_BINARY_DIR}/${name}_rt_labels.cmake")
    file(WRITE "${script}"
      "# Generated by hiltwin_add_gtest: adds the rt label to the wall-clock tests.\n"
      "foreach(test IN LISTS ${name}_TESTS)\n"
      "  if(test MATCHES [=[${ARG_RT_TESTS}]=])\n"
      "    set_tests_properties(\"\${test}\" PROPERTIES LABELS \"${rt_labels}\")\n"
      "  endif()\n"
      "endforeach()\n")
    # Appended after gtest_discover_tests's own include file, so it runs after discovery.
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${script}")
  endif()
endfunction()
