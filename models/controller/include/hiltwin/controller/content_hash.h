#pragma once
// The SHA-256 of a controller's file, for ControllerInfo::content_sha256: the run report names
// it so a result can be traced to the exact code that produced it (issue 37, item 4). Public:
// the FMU controller (models/fmi) hashes its .fmu with it too.

#include <filesystem>
#include <string>

namespace hiltwin::controller {

/// The SHA-256 of the bytes of `file`, 64 lower-case hex digits. Not real-time (reads the whole
/// file). Throws ControllerError naming the file when it cannot be read.
[[nodiscard]] std::string Sha256HexOfFile(const std::filesystem::path& file);

}  // namespace hiltwin::controller
