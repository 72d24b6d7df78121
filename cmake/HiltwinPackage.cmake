# CPack: the install components of cmake/HiltwinInstall.cmake as Debian packages,
#   hiltwin      (runtime) the command; Depends from dpkg-shlibdeps, i.e. the Debian runtime
#                libraries the binary really links (libspdlog1.10, liblttng-ust1, libc6...)
#   hiltwin-dev  (dev) headers, static libraries, CMake package; Depends on hiltwin of the same
#                version and on the -dev packages hiltwinConfig.cmake finds
# `cpack -G DEB` in a build folder makes both; scripts/package.sh builds a release folder for
# amd64 or arm64 and runs it. The architecture is the target's, so a cross build (cmake/
# toolchains/aarch64-linux-gnu.cmake) packages arm64.

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME hiltwin)
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
# The repository's maintainers; a release may name others (-DHILTWIN_PACKAGE_MAINTAINER=...).
set(HILTWIN_PACKAGE_MAINTAINER
    "hiltwin maintainers <maintainers@users.noreply.h-seed-1b4fd92b.example>"
    CACHE STRING "Maintainer field of the .deb packages: Name <email>")
set(HILTWIN_PACKAGE_HOMEPAGE "" CACHE STRING "Homepage field of the .deb packages (empty: none)")
set(CPACK_PACKAGE_CONTACT "${HILTWIN_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${HILTWIN_PACKAGE_MAINTAINER}")
if(HILTWIN_PACKAGE_HOMEPAGE)
  set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "${HILTWIN_PACKAGE_HOMEPAGE}")
endif()
# The license (Apache-2.0, LICENSE) ships as /usr/share/doc/hiltwin/LICENSE: a .deb's control
# file has no field for it.
# Debian policy: binaries ship stripped (the static libraries keep their symbols: CMake strips
# executables only).
set(CPACK_STRIP_FILES ON)

# One package per component; Unspecified (an install rule without COMPONENT) ships in neither.
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # hiltwin_0.1.0_amd64.deb
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME hiltwin)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION electronics)
# The synopsis of both packages is CPACK_PACKAGE_DESCRIPTION_SUMMARY (the project's description):
# CPackDeb puts it before each component's description, the extended text.
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION
    "hiltwin runs a plant model (a digital twin) in real time behind the same
electrical interface as the real plant, an FPGA reached over SPI, checks every
deadline and says whether the run can be trusted: PASS, FLAGGED or ABORTED.
This package holds the hiltwin command: run, ecs, hil, trace, monitor, tune,
assess, doctor and io-test, with the RELbot case study and its configuration.")
# `hiltwin assess --plot` and the trace pictures run gnuplot; `hiltwin trace` needs an LTTng
# session daemon. Both are optional: the commands say so when they are missing.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "gnuplot-nox, lttng-tools")

set(CPACK_DEBIAN_DEV_PACKAGE_NAME hiltwin-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_COMPONENT_DEV_DESCRIPTION
    "This package holds the development files: headers, static libraries and the
CMake package of hiltwin's framework, for plants and controllers built outside
hiltwin. find_package(hiltwin) gives hiltwin::runtime, hiltwin::io,
hiltwin::plant, hiltwin::fmi and the layers below them (lockfree, kernel_glue, scheduler,
qos, lifecycle, tracing), and the C ABI of a controller library (hiltwin/controller_abi.h,
hiltwin::controller_abi, hiltwin_add_controller) for hiltwin ecs --controller lib:PATH.so.")
# hiltwin-dev Depends on hiltwin (= this version): component dependencies become package ones.
set(CPACK_COMPONENT_DEV_DEPENDS runtime)
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
# What cmake/hiltwinConfig.cmake.in finds, as Debian names it (Threads is libc's).
set(dev_depends libspdlog-dev "nlohmann-json3-dev (>= 3.11)" libtomlplusplus-dev libxml2-dev
    libzip-dev libssl-dev pkg-config)
if(HILTWIN_WITH_LTTNG)
  list(APPEND dev_depends liblttng-ust-dev)
endif()
list(JOIN dev_depends ", " CPACK_DEBIAN_DEV_PACKAGE_DEPENDS)
# The headers are C++20 as g++ 12 implements it (top-level CMakeLists.txt).
set(CPACK_DEBIAN_DEV_PACKAGE_RECOMMENDS "cmake (>= 3.25), g++ (>= 4:12)")

# The target's Debian architecture: dpkg's own natively; from the toolchain when cross-compiling,
# where dpkg would name the build machine's. dpkg-shlibdeps then reads the target's libraries
# through multiarch (/usr/lib/aarch64-linux-gnu), so it needs nothing more for a cross build.
function(hiltwin_debian_architecture out)
  if(CMAKE_CROSSCOMPILING)
    if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64|AARCH64|ARM64)$")
      set(arch arm64)
    elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|amd64|AMD64)$")
      set(arch amd64)
    elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^armv7")
      set(arch armhf)
    else()
      message(FATAL_ERROR "HiltwinPackage: no Debian architecture known for "
              "CMAKE_SYSTEM_PROCESSOR '${CMAKE_SYSTEM_PROCESSOR}' (toolchain "
              "${CMAKE_TOOLCHAIN_FILE}): configure with -DCPACK_DEBIAN_PACKAGE_ARCHITECTURE=<arch>")
    endif()
  else()
    find_program(HILTWIN_DPKG dpkg)
    if(NOT HILTWIN_DPKG)
      return()  # not a Debian machine: cpack -G DEB says what is missing, the build does not
    endif()
    execute_process(COMMAND "${HILTWIN_DPKG}" --print-architecture OUTPUT_VARIABLE arch
                    OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
  endif()
  set(${out} "${arch}" PARENT_SCOPE)
endfunction()
if(NOT CPACK_DEBIAN_PACKAGE_ARCHITECTURE)
  hiltwin_debian_architecture(CPACK_DEBIAN_PACKAGE_ARCHITECTURE)
endif()

include(CPack)
