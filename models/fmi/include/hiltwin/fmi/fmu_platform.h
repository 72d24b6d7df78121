#pragma once
/// The folder under an FMU's binaries/ whose shared library hiltwin loads on this machine:
/// "linux64" (FMI 2.0's name for x86-64 Linux) or "aarch64-linux" (arm64, the Raspberry Pi,
/// with FMI 3.0's platform tuple, as FMI tools write it into 2.0 archives too). CMake sets it
/// once for the build's target architecture (HILTWIN_FMU_PLATFORM, top-level CMakeLists.txt).

#include <string_view>

namespace hiltwin::fmi {

inline constexpr std::string_view kFmuPlatform = HILTWIN_FMU_PLATFORM;
/// The platform in words, for messages: "Linux x86-64", "Linux arm64".
inline constexpr std::string_view kFmuPlatformName = HILTWIN_FMU_PLATFORM_NAME;

}  // namespace hiltwin::fmi
