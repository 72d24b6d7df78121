# Cross build for arm64 (the Raspberry Pi 4 of the thesis) with Debian's own cross toolchain and
# its arm64 libraries through multiarch, no sysroot to assemble:
#   bash scripts/setup.sh --cross arm64        # crossbuild-essential-arm64, qemu, libfoo-dev:arm64
#   cmake -S . -B build-arm64 --toolchain cmake/toolchains/aarch64-linux-gnu.cmake
# Multiarch puts every arm64 library and pkg-config file under /usr/lib/aarch64-linux-gnu and
# shares the architecture-independent headers in /usr/include, so the search below keeps the
# host's root but sends pkg-config to the arm64 .pc files. Tests run under qemu-aarch64-static
# (CMAKE_CROSSCOMPILING_EMULATOR, also used by CTest and by gtest discovery).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# qemu finds the arm64 loader and libraries at their multiarch paths on this host; the search
# prefix is only for a library a distribution puts elsewhere.
find_program(HILTWIN_QEMU_AARCH64 NAMES qemu-aarch64-static qemu-aarch64)
if(HILTWIN_QEMU_AARCH64)
  set(CMAKE_CROSSCOMPILING_EMULATOR "${HILTWIN_QEMU_AARCH64}")
endif()

# Programs (idlc, verilator, help2man) are the host's; libraries, headers and packages the
# target's. Only the architecture-specific directories separate the two here, which the
# compiler and CMAKE_LIBRARY_ARCHITECTURE already do.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)

# pkg-config: the arm64 .pc files, not the host's (which would link x86-64 libraries).
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
