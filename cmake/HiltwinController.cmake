# hiltwin_add_controller(<name> <sources...>): a controller library for
# `hiltwin ecs|hil --controller lib:<name>.so`, built from C or C++ against the C ABI of
# hiltwin/controller_abi.h (docs/controller-abi.md). A MODULE library named <name>.so (no "lib"
# prefix, so the file is what the student named it) that exports only hiltwin_controller: the
# header marks it default-visible, everything else is hidden, so two controllers never clash.
# It links nothing of hiltwin (hiltwin::controller_abi is the header alone).
# The same file serves hiltwin's own build (models/controller/CMakeLists.txt includes it, for
# the example and the test controllers) and an installed hiltwin (hiltwinConfig.cmake includes
# it, so a user's CMakeLists gets it with find_package(hiltwin)).
function(hiltwin_add_controller name)
  if(NOT ARGN)
    message(FATAL_ERROR "hiltwin_add_controller(${name}): give the controller's source files, "
                        "e.g. hiltwin_add_controller(${name} ${name}.c)")
  endif()
  add_library(${name} MODULE ${ARGN})
  target_link_libraries(${name} PRIVATE hiltwin::controller_abi)
  set_target_properties(${name} PROPERTIES PREFIX "" SUFFIX ".so" C_VISIBILITY_PRESET hidden
                        CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
endfunction()
