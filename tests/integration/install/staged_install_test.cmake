# Install.StagedPrefixBuildsAnOutOfTreeTwin (cmake -P; CMakeLists.txt here passes the -D values):
# `cmake --install` of this build folder into an empty prefix, then examples/lag_twin
# configured, built and run against that prefix with find_package(hiltwin), as a user's own
# project would be. The example is a plant stepped by the run assembly on the emulated board.
# Last, docs/controllers.md's "Your first controller" is followed as a student would, against
# the same prefix (doc_blocks.cmake).
# In: BUILD_DIR, SOURCE_DIR, WORK_DIR, VERSION, GENERATOR, CXX_COMPILER; TOOLCHAIN_FILE and
# EMULATOR when cross-compiling.
cmake_minimum_required(VERSION 3.25)
include("${CMAKE_CURRENT_LIST_DIR}/test_steps.cmake")
include("${CMAKE_CURRENT_LIST_DIR}/doc_blocks.cmake")
hiltwin_test_require_vars(BUILD_DIR SOURCE_DIR WORK_DIR VERSION GENERATOR)

# The targets a plant or controller needs (the issue's contract, cmake/HiltwinInstall.cmake).
set(required_targets kernel_glue scheduler qos lifecycle io tracing runtime plant fmi
    controller_abi)

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
set(stage "${WORK_DIR}/stage")
hiltwin_test_run("install into a staging prefix" out
  COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${stage}"
  HINT "build the tree first (cmake --build ${BUILD_DIR}), then see "
       "cmake/HiltwinInstall.cmake")
set(installed bin/hiltwin include/hiltwin/runtime/run_session.h include/hiltwin/io/backend.h
    include/hiltwin/plant/plant.h include/hiltwin/controller_abi.h share/hiltwin/relbot.toml
    share/hiltwin/config/cyclonedds-loopback.xml
    share/hiltwin/ros2/hiltwin_msgs/msg/Timing.msg share/doc/hiltwin/README.md
    share/bash-completion/completions/hiltwin)
if(EXISTS "${BUILD_DIR}/hiltwin.1")  # only where help2man is (cmake/GenerateManPage.cmake)
  list(APPEND installed share/man/man1/hiltwin.1)
endif()
hiltwin_test_require_files("the staged install" "install it in cmake/HiltwinInstall.cmake"
                           "${stage}" ${installed})

# The CMake package: every required target exported, and nothing pointing back into the tree
# (a path of the source or build folder would break on any other machine).
file(GLOB_RECURSE package_files "${stage}/*/hiltwinConfig.cmake"
     "${stage}/*/hiltwinTargets*.cmake")
list(FILTER package_files INCLUDE REGEX "/cmake/hiltwin/")
if(NOT package_files)
  hiltwin_test_fail("the staged install"
                    WHY "no <libdir>/cmake/hiltwin/hiltwinConfig.cmake under ${stage}"
                    HINT "install the package files in cmake/HiltwinInstall.cmake")
endif()
set(exported "")
foreach(file IN LISTS package_files)
  file(READ "${file}" text)
  foreach(tree "${SOURCE_DIR}" "${BUILD_DIR}")
    string(FIND "${text}" "${tree}" at)
    if(NOT at EQUAL -1)
      hiltwin_test_fail("the installed CMake package" WHY "${file} names ${tree}"
                        HINT "wrap tree paths in $<BUILD_INTERFACE:...> "
                             "(hiltwin_add_module in cmake/HiltwinTargets.cmake)")
    endif()
  endforeach()
  string(REGEX MATCHALL "add_library\\(hiltwin::[a-z_0-9]+" added "${text}")
  list(APPEND exported ${added})
endforeach()
foreach(name IN LISTS required_targets)
  if(NOT "add_library(hiltwin::${name}" IN_LIST exported)
    hiltwin_test_fail("the installed CMake package" WHY "it does not export hiltwin::${name}"
                      HINT "add ${name} to HILTWIN_EXPORTED_MODULES (cmake/HiltwinInstall.cmake)")
  endif()
endforeach()

hiltwin_test_check_version("the installed hiltwin --version" "${stage}/bin/hiltwin")

# The example as a user builds it: only CMAKE_PREFIX_PATH says where hiltwin is.
set(example "${WORK_DIR}/example")
set(configure_args -S "${SOURCE_DIR}/examples/lag_twin" -B "${example}" -G "${GENERATOR}"
    "-DCMAKE_PREFIX_PATH=${stage}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    "-DCMAKE_CXX_FLAGS=-Werror")  # the example's own warnings (hiltwin's headers are SYSTEM)
if(TOOLCHAIN_FILE)
  list(APPEND configure_args "--toolchain" "${TOOLCHAIN_FILE}")
elseif(CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
hiltwin_test_run("configure the out-of-tree example" out
  COMMAND "${CMAKE_COMMAND}" ${configure_args}
  HINT "if find_package(hiltwin) failed: its dependencies are found by "
       "cmake/hiltwinConfig.cmake.in")
file(STRINGS "${example}/CMakeCache.txt" found_dir REGEX "^hiltwin_DIR:")
if(NOT found_dir MATCHES "=${stage}/")
  hiltwin_test_fail("configure the out-of-tree example" WHY "it found ${found_dir}, not ${stage}"
                    HINT "remove the other hiltwin from CMAKE_PREFIX_PATH")
endif()
hiltwin_test_run("build the out-of-tree example" out
  COMMAND "${CMAKE_COMMAND}" --build "${example}"
  HINT "the installed headers or libraries do not build a user's twin")

hiltwin_test_run("run the out-of-tree example" out EXIT_CODES 0 3
  COMMAND ${EMULATOR} "${example}/lag_twin")
hiltwin_test_check_verdict("run the out-of-tree example" "${out}" "${out_EXIT}")
# examples/lag_twin/lag_twin.cpp: y = 0.5 (1 - 0.99^1000) after 1000 Euler steps, 499 counts.
set(result_line "lag_twin: y = ([0-9.]+) m after ([0-9]+) steps, encoder 1 at (-?[0-9]+) counts")
if(NOT out MATCHES "${result_line}")
  hiltwin_test_fail("run the out-of-tree example" WHY "no result line in:\n${out}"
                    HINT "see examples/lag_twin/lag_twin.cpp")
endif()
set(y "${CMAKE_MATCH_1}")
set(steps "${CMAKE_MATCH_2}")
set(counts "${CMAKE_MATCH_3}")
if(NOT steps EQUAL 1000 OR NOT counts EQUAL 499 OR y LESS 0.4999 OR y GREATER 0.5)
  hiltwin_test_fail("run the out-of-tree example"
    WHY "y = ${y} m after ${steps} steps at ${counts} counts; expected y in [0.4999, 0.5] "
        "after 1000 steps at 499 counts"
    HINT "the plant map, the emulated board or RunSession no longer behave as "
         "examples/lag_twin/lag_twin.cpp says")
endif()
message(STATUS "out-of-tree example: y = ${y} m after ${steps} steps, ${counts} counts")

# The C controller example as a student builds it: a C project of its own, found hiltwin with
# find_package, hiltwin_add_controller, the installed hiltwin/controller_abi.h. Then the loader
# (tests/controllers' probe) steps the library it made with known inputs. The PD law itself is
# checked by hand in tests/unit/controller_abi against the in-tree build of the same source;
# here the out-of-tree library must step exactly as that one, and hold the values that need no
# gains: no error gives zero duty, a metre of error gives full duty each way.
if(PROBE AND IN_TREE_CONTROLLER_DIR)
  set(controller "${WORK_DIR}/controller_c_pd")
  set(configure_args -S "${SOURCE_DIR}/examples/controller_c_pd" -B "${controller}"
      -G "${GENERATOR}" "-DCMAKE_PREFIX_PATH=${stage}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
      "-DCMAKE_C_FLAGS=-Wall -Wextra -Wpedantic -Wconversion -Wshadow -Werror")
  if(TOOLCHAIN_FILE)
    list(APPEND configure_args "--toolchain" "${TOOLCHAIN_FILE}")
  elseif(C_COMPILER)
    list(APPEND configure_args "-DCMAKE_C_COMPILER=${C_COMPILER}")
  endif()
  hiltwin_test_run("configure the C controller example" out
    COMMAND "${CMAKE_COMMAND}" ${configure_args}
    HINT "find_package(hiltwin) in a C-only project: cmake/hiltwinConfig.cmake.in and "
         "cmake/HiltwinController.cmake")
  hiltwin_test_run("build the C controller example" out
    COMMAND "${CMAKE_COMMAND}" --build "${controller}"
    HINT "the installed hiltwin/controller_abi.h or hiltwin_add_controller do not build it")
  hiltwin_test_require_files("the C controller example"
                             "see hiltwin_add_controller in cmake/HiltwinController.cmake"
                             "${controller}" my_pd.so)
  set(steps "0,0,0,0" "0.001,-0.001,0,0" "1,-1,0,0")
  hiltwin_test_run("step the out-of-tree controller" out
    COMMAND ${EMULATOR} "${PROBE}" "${controller}/my_pd.so" 0.001 ${steps})
  hiltwin_test_run("step the in-tree controller" in_tree
    COMMAND ${EMULATOR} "${PROBE}" "${IN_TREE_CONTROLLER_DIR}/my_pd.so" 0.001 ${steps})
  if(NOT out STREQUAL in_tree)
    hiltwin_test_fail("step the out-of-tree controller"
      WHY "it stepped\n${out}but the in-tree build of the same source stepped\n${in_tree}"
      HINT "the installed header or hiltwin_add_controller build it differently")
  endif()
  set(expected "^step 1: duty_left=0 duty_right=0\n"
      "step 2: duty_left=([0-9.e-]+) duty_right=(-[0-9.e-]+)\n"
      "step 3: duty_left=1 duty_right=-1\n$")
  string(CONCAT expected ${expected})
  set(duty_left "")
  set(duty_right "")
  if(out MATCHES "${expected}")  # its own if: ${CMAKE_MATCH_n} expands before an if runs
    set(duty_left "${CMAKE_MATCH_1}")
    set(duty_right "${CMAKE_MATCH_2}")
  endif()
  if(duty_left STREQUAL "" OR NOT duty_left GREATER 0 OR NOT duty_left LESS 1
     OR NOT duty_right STREQUAL "-${duty_left}")
    hiltwin_test_fail("step the out-of-tree controller"
      WHY "it stepped\n${out}expected zero duty, then a duty in (0, 1) and its negative, then "
          "exactly 1 and -1"
      HINT "see examples/controller_c_pd/my_pd.c")
  endif()
  message(STATUS "out-of-tree controller: ${out}")
endif()

# docs/controllers.md, "Your first controller", as a student follows it: its run blocks in a
# fresh folder holding a copy of the example, with the staged hiltwin found as the page tells a
# student to (PATH and CMAKE_PREFIX_PATH in the environment), so its lines run verbatim; its
# file blocks equal the example, its lockstep output is the real one. The real-time run is run
# too (12 s; exit 0 or 3, its figures are the machine's): it is the page's second command a
# student types, and the only check that the page's real-time line still runs. Left out when
# cross-compiling: the staged hiltwin is another machine's.
if(NOT EMULATOR AND NOT TOOLCHAIN_FILE)
  set(RUN_DIR "${WORK_DIR}/tutorial")
  file(COPY "${SOURCE_DIR}/examples/controller_c_pd/" DESTINATION "${RUN_DIR}")
  file(REMOVE_RECURSE "${RUN_DIR}/build")  # a student's copy has no build folder yet
  set(ENV{PATH} "${stage}/bin:$ENV{PATH}")
  set(ENV{CMAKE_PREFIX_PATH} "${stage}")
  set(ENV{CMAKE_GENERATOR} "${GENERATOR}")
  if(C_COMPILER)
    set(ENV{CC} "${C_COMPILER}")
  endif()
  string(TIMESTAMP tutorial_start_s "%s")
  hiltwin_doc_blocks("${SOURCE_DIR}/docs/controllers.md")
  string(TIMESTAMP tutorial_end_s "%s")
  math(EXPR tutorial_s "${tutorial_end_s} - ${tutorial_start_s}")
  if(doc_blocks_checked LESS 6)
    hiltwin_test_fail("docs/controllers.md" WHY "${doc_blocks_checked} tagged blocks, not 6"
                      HINT "the tutorial lost its tags (doc_blocks.cmake): put them back")
  endif()
  message(STATUS "docs/controllers.md: ${doc_blocks_checked} tagged blocks checked, "
                 "${tutorial_s} s")
endif()
