#pragma once
// The parts of an FMU's zip a run needs, unpacked into a private folder that lives as long as
// this object.

#include <filesystem>
#include <string>
#include <string_view>

#include "hiltwin/fmi/fmu_plant.h"

namespace hiltwin::fmi {

class UnpackedFmu {
 public:
  /// Unpacks what running `fmu_path` needs (modelDescription.xml, binaries/<kFmuPlatform>/,
  /// resources/) into a new mkdtemp folder (mode 0700) under $TMPDIR or /tmp; other entries
  /// (documentation, sources, other platforms) stay in the archive. Entries with an absolute
  /// path or a ".." component are refused, so an archive cannot write outside the folder; so
  /// is an archive of more entries or bytes than `limits`. Throws plant::PlantError naming the
  /// file, the entry and, for a cap, the cap and the value seen.
  UnpackedFmu(const std::filesystem::path& fmu_path, const FmuUnpackLimits& limits);
  ~UnpackedFmu();
  UnpackedFmu(const UnpackedFmu&) = delete;
  UnpackedFmu& operator=(const UnpackedFmu&) = delete;

  [[nodiscard]] const std::filesystem::path& dir() const noexcept { return dir_; }
  /// The platforms the archive has binaries for ("linux64, win64"; "none"), unpacked or not.
  [[nodiscard]] const std::string& binary_platforms() const noexcept { return platforms_; }

 private:
  std::filesystem::path dir_;
  std::string platforms_;
};

/// True when a zip entry name stays inside the folder it is unpacked into: relative, no ".."
/// component (either slash counts: archives made on Windows use backslashes).
[[nodiscard]] bool IsSafeEntryName(std::string_view name) noexcept;

}  // namespace hiltwin::fmi
