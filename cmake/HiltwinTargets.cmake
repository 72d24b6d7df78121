# Shared target set-up: one place for the warning set, sanitizers, modules and tests.

# Warning set applied to every target of ours, tests and benchmarks included.
function(hiltwin_target_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wnon-virtual-dtor
    -Wold-style-cast -Woverloaded-virtual -Wdouble-promotion -Wformat=2
    -Wimplicit-fallthrough -Wcast-align -Wmisleading-indentation)
  if(HILTWIN_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# Sanitizers are global so that every object, including GoogleTest's main, agrees.
macro(hiltwin_apply_sanitizers)
  if(HILTWIN_SANITIZE)
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
#                   [TIMEOUT s])
# A GoogleTest executable whose tests CTest discovers one by one, with labels
# (unit, integration, rt, soak) so suites can be chosen with `ctest -L`.
function(hiltwin_add_gtest name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  hiltwin_target_warnings(${name})
  gtest_discover_tests(${name}
    DISCOVERY_TIMEOUT 60
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
    EXTRA_ARGS --gtest_color=no)
endfunction()
