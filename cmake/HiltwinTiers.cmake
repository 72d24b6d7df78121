# Tiers: the top-level folders, and which of them a module may depend on (docs/architecture.md).
# A module's tier is the first folder of its path under the project's source folder, so moving
# a module moves its rights with it. Arrows point down only: the loop (engine) knows nothing of
# the boards, models, case study, tools or program built on it; a model knows the engine; the
# RELbot knows the engine and the models; the tools outside the loop (observe) know the engine
# and each other; the program (cli) may use anything. hiltwin_add_module calls
# hiltwin_check_tier, so an upward dependency is a configure error naming both modules.
set(HILTWIN_TIER_MAY_USE_engine engine)
set(HILTWIN_TIER_MAY_USE_board engine board)
set(HILTWIN_TIER_MAY_USE_models engine models)
set(HILTWIN_TIER_MAY_USE_relbot engine models relbot)
set(HILTWIN_TIER_MAY_USE_observe engine observe)
set(HILTWIN_TIER_MAY_USE_cli engine board models relbot observe cli)

# hiltwin_check_tier(<module> <dependencies...>): records the tier of <module> (from the folder
# being configured) and refuses any module among the dependencies whose tier <module>'s may
# not use. Targets that are not modules (Threads::Threads, hiltwin_fpga_rtl, ...) are not
# checked.
function(hiltwin_check_tier name)
  file(RELATIVE_PATH folder "${PROJECT_SOURCE_DIR}" "${CMAKE_CURRENT_SOURCE_DIR}")
  string(REGEX MATCH "^[^/]+" tier "${folder}")
  if(NOT DEFINED HILTWIN_TIER_MAY_USE_${tier})
    message(FATAL_ERROR "module ${name} is in ${folder}/, outside every tier: a module lives under "
                        "engine/, board/, models/, relbot/, observe/ or cli/ "
                        "(docs/architecture.md)")
  endif()
  set_property(GLOBAL PROPERTY HILTWIN_TIER_OF_${name} ${tier})
  foreach(dep IN LISTS ARGN)
    # A module is listed as hiltwin::<name> or by its target, hiltwin_<name>. Only the alias
    # must name a module; hiltwin_fpga_rtl and the like are not modules and are not checked.
    if(NOT dep MATCHES "^hiltwin(::|_)(.+)$")
      continue()
    endif()
    set(used ${CMAKE_MATCH_2})
    get_property(used_tier GLOBAL PROPERTY HILTWIN_TIER_OF_${used})
    if(NOT used_tier AND CMAKE_MATCH_1 STREQUAL "_")
      continue()
    endif()
    if(NOT used_tier)
      message(FATAL_ERROR "module ${name} (${folder}/) lists hiltwin::${used}, which is not a "
                          "module added before it: add its folder earlier in "
                          "HILTWIN_MODULE_FOLDERS (CMakeLists.txt)")
    endif()
    if(NOT used_tier IN_LIST HILTWIN_TIER_MAY_USE_${tier})
      string(REPLACE ";" ", " allowed "${HILTWIN_TIER_MAY_USE_${tier}}")
      message(FATAL_ERROR "module ${name} (tier ${tier}) may not depend on module ${used} (tier "
                          "${used_tier}): ${tier}/ may use only ${allowed}. Move the code both "
                          "need down a tier, or the user up (docs/architecture.md, \"Tiers\")")
    endif()
  endforeach()
endfunction()
