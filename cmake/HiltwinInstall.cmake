# `cmake --install`: what hiltwin installs, in two components that cmake/HiltwinPackage.cmake
# turns into the Debian packages hiltwin and hiltwin-dev:
#   runtime  bin/hiltwin, its example configuration files (share/hiltwin) and the documents
#   dev      the headers, static libraries and CMake package of the modules a user's plant or
#            controller builds on: find_package(hiltwin) gives hiltwin::<module>
# Included from the top-level CMakeLists.txt once every module exists.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The engine and the models (docs/architecture.md, "Tiers"). The RELbot, the tools outside the
# loop (observe/) and the program (cli/) stay inside the binary: they would pull Cyclone DDS,
# FFTW and babeltrace into every user's link for nothing a plant or controller needs.
set(HILTWIN_EXPORTED_MODULES lockfree kernel_glue scheduler qos lifecycle io tracing runtime plant
    controller fmi)
set(HILTWIN_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/hiltwin")
set(HILTWIN_INSTALL_DATADIR "${CMAKE_INSTALL_DATADIR}/hiltwin")

set(exported_targets)
foreach(module IN LISTS HILTWIN_EXPORTED_MODULES)
  list(APPEND exported_targets hiltwin_${module})
  # Each module's headers sit under <module>/include/hiltwin/<module>/, so they all merge into
  # one <prefix>/include/hiltwin/ and keep their #include "hiltwin/<module>/..." paths.
  get_target_property(module_dir hiltwin_${module} SOURCE_DIR)
  install(DIRECTORY "${module_dir}/include/" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
          COMPONENT dev)
endforeach()
# The C ABI of a controller library (hiltwin/controller_abi.h): the header alone, as the
# INTERFACE target hiltwin::controller_abi, with hiltwin_add_controller to build a library
# against it (cmake/HiltwinController.cmake, included by hiltwinConfig.cmake). The controller
# module's C++ headers stay inside the binary with the module.
install(FILES "${PROJECT_SOURCE_DIR}/models/controller/include/hiltwin/controller_abi.h"
        DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/hiltwin" COMPONENT dev)
list(APPEND exported_targets hiltwin_controller_abi)
install(FILES "${PROJECT_SOURCE_DIR}/cmake/HiltwinController.cmake"
        DESTINATION "${HILTWIN_INSTALL_CMAKEDIR}" COMPONENT dev)
install(TARGETS ${exported_targets} EXPORT hiltwinTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT dev
        INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(EXPORT hiltwinTargets NAMESPACE hiltwin:: DESTINATION "${HILTWIN_INSTALL_CMAKEDIR}"
        COMPONENT dev)

configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/hiltwinConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/hiltwinConfig.cmake"
                              INSTALL_DESTINATION "${HILTWIN_INSTALL_CMAKEDIR}")
# 0.x: a minor release may change the modules' interfaces, so only patch releases are taken as
# compatible. The file also refuses a hiltwin built for another pointer size (static libraries).
write_basic_package_version_file("${PROJECT_BINARY_DIR}/hiltwinConfigVersion.cmake"
                                 COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/hiltwinConfig.cmake"
              "${PROJECT_BINARY_DIR}/hiltwinConfigVersion.cmake"
        DESTINATION "${HILTWIN_INSTALL_CMAKEDIR}" COMPONENT dev)

install(TARGETS hiltwin RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}" COMPONENT runtime)

# The documented starting points for --config, --gains and --plant-map, and the Cyclone DDS
# configuration for machines without multicast (its messages name <hiltwin>/config/).
file(GLOB relbot_configs "${PROJECT_SOURCE_DIR}/relbot/*.toml")
install(FILES ${relbot_configs} DESTINATION "${HILTWIN_INSTALL_DATADIR}" COMPONENT runtime)
install(DIRECTORY "${PROJECT_SOURCE_DIR}/config/" DESTINATION "${HILTWIN_INSTALL_DATADIR}/config"
        COMPONENT runtime)
# The ROS 2 interface package of the Timing type, for a user of the package to copy into a ROS 2
# workspace (docs/telemetry.md); hiltwin itself does not build it.
install(DIRECTORY "${PROJECT_SOURCE_DIR}/ros2/hiltwin_msgs"
        DESTINATION "${HILTWIN_INSTALL_DATADIR}/ros2" COMPONENT runtime)

# The man page and the bash completion, made by the built binary (cmake/GenerateManPage.cmake
# names them <binary>.<ext> in the build folder; a cross build without an emulator, or a machine
# without help2man, has no target for them, and they are left out).
if(TARGET hiltwin_man_page)
  install(FILES "${PROJECT_BINARY_DIR}/hiltwin.1" DESTINATION "${CMAKE_INSTALL_MANDIR}/man1"
          COMPONENT runtime)
endif()
if(TARGET hiltwin_bash_completion)
  # bash-completion loads completions/<command> the first time <command> is completed.
  install(FILES "${PROJECT_BINARY_DIR}/hiltwin.bash" RENAME hiltwin
          DESTINATION "${CMAKE_INSTALL_DATADIR}/bash-completion/completions"
          COMPONENT runtime)
endif()

# LICENSE and CHANGELOG.md are optional here, so a tree without them still installs. docs/
# goes beside README.md, whose links name docs/<file>.md.
foreach(document README.md LICENSE CHANGELOG.md)
  if(EXISTS "${PROJECT_SOURCE_DIR}/${document}")
    install(FILES "${PROJECT_SOURCE_DIR}/${document}" DESTINATION "${CMAKE_INSTALL_DOCDIR}"
            COMPONENT runtime)
  endif()
endforeach()
install(DIRECTORY "${PROJECT_SOURCE_DIR}/docs" DESTINATION "${CMAKE_INSTALL_DOCDIR}"
        COMPONENT runtime FILES_MATCHING PATTERN "*.md")
