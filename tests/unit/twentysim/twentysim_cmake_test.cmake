# cmake -DSOURCE_DIR=<hiltwin> -DWORK_DIR=<scratch> -P twentysim_cmake_test.cmake
#
# What cmake/TwentySimPlant.cmake does with a 20-sim plant and a 20-sim controller in one build,
# configured as a small project of its own: (1) msd20sim and pid20sim, both LoopController with
# the same support files, configure; the plant's xxinteg.cpp becomes one support library in the
# plants' list and the controller compiles only its class; (2) a controller folder whose
# xxinteg.h differs is refused, naming both files.

function(fail what)
  message(FATAL_ERROR "FAILED: ${what}\n  what to do: compare with docs/20sim.md (Limits) and "
          "cmake/TwentySimPlant.cmake's _hiltwin_20sim_share_support")
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}/project")
file(COPY "${SOURCE_DIR}/models/controllers/pid20sim/" DESTINATION "${WORK_DIR}/pid_other")
file(APPEND "${WORK_DIR}/pid_other/xxinteg.h" "/* another 20-sim version */\n")

set(ports_pid INPUTS setpoint_left_m:m setpoint_right_m:m wheel_left_m:m wheel_right_m:m
              OUTPUTS duty_left:1 duty_right:1)
file(WRITE "${WORK_DIR}/project/CMakeLists.txt" "
cmake_minimum_required(VERSION 3.25)
project(twentysim_cmake_test CXX)
add_library(stub INTERFACE)
add_library(hiltwin::plant ALIAS stub)
add_library(hiltwin::controller ALIAS stub)
function(hiltwin_target_warnings target)
endfunction()
include(\"${SOURCE_DIR}/cmake/TwentySimPlant.cmake\")
hiltwin_add_20sim_plant(msd CLASS LoopController INPUTS force_n:N
  OUTPUTS position_m:m velocity_m_per_s:m/s DIR \"${SOURCE_DIR}/models/plants/msd20sim\")
hiltwin_add_20sim_controller(pid CLASS LoopController ${ports_pid} DIR \"\${PID_DIR}\")
get_property(plants GLOBAL PROPERTY HILTWIN_PLANT_LIBRARIES)
get_property(controllers GLOBAL PROPERTY HILTWIN_CONTROLLER_LIBRARIES)
get_target_property(pid_sources hiltwin_controller_pid SOURCES)
message(STATUS \"plants=\${plants}\")
message(STATUS \"controllers=\${controllers}\")
message(STATUS \"pid_sources=\${pid_sources}\")
")

function(configure out_result out_text pid_dir build)
  execute_process(COMMAND "${CMAKE_COMMAND}" -S "${WORK_DIR}/project" -B "${WORK_DIR}/${build}"
                          "-DPID_DIR=${pid_dir}"
                  RESULT_VARIABLE result OUTPUT_VARIABLE text ERROR_VARIABLE text)
  set(${out_result} "${result}" PARENT_SCOPE)
  set(${out_text} "${text}" PARENT_SCOPE)
endfunction()

# (1) the same support files: one build.
configure(result text "${SOURCE_DIR}/models/controllers/pid20sim" same)
if(NOT result EQUAL 0)
  fail("a plant and a controller with the same support files did not configure:\n${text}")
endif()
if(NOT text MATCHES "plants=hiltwin_20sim_support_xxinteg_[0-9a-f]+;hiltwin_plant_msd\n")
  fail("the plants' list is not the shared xxinteg support library and the plant:\n${text}")
endif()
if(NOT text MATCHES "controllers=hiltwin_controller_pid\n")
  fail("the controllers' list is not the controller alone (xxinteg compiled twice?):\n${text}")
endif()
if(NOT text MATCHES "pid_sources=[^\n]*/pid20sim/LoopController.cpp;[^\n;]*_register.cpp\n")
  fail("the controller does not compile exactly its class and its registration:\n${text}")
endif()

# (2) a support header that differs: refused at configure time.
configure(result text "${WORK_DIR}/pid_other" other)
if(result EQUAL 0)
  fail("a controller whose xxinteg.h differs from the plant's configured")
endif()
string(REGEX REPLACE "[ \n]+" " " text "${text}")  # CMake wraps its messages
set(expected "hiltwin_add_20sim_controller\\(pid\\): [^ ]*/pid_other/xxinteg.h differs from ")
string(APPEND expected "the xxinteg.h of hiltwin_add_20sim_plant\\(msd\\)")
if(NOT text MATCHES "${expected}")
  fail("the refusal does not name both files:\n${text}")
endif()
message(STATUS "PASSED")
