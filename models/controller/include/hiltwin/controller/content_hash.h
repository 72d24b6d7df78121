#pragma once
/// The SHA-256 of a controller's file (ControllerInfo::content_sha256), so a run report names
/// the exact code that produced its result. For the loaders of every file kind (lib:, fmu:,
/// 20-sim sources).

#include <filesystem>
#include <string>

namespace hiltwin::controller {

/// The SHA-256 of `path`'s bytes as 64 lower-case hex digits. Throws ControllerError naming
/// the file when it cannot be read.
[[nodiscard]] std::string FileSha256(const std::filesystem::path& path);

}  // namespace hiltwin::controller
