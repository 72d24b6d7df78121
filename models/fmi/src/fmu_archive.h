#pragma once
// An FMU's zip unpacked into a private folder that lives as long as this object.

#include <filesystem>
#include <string_view>

namespace hiltwin::fmi {

class UnpackedFmu {
 public:
  /// Unpacks `fmu_path` into a new mkdtemp folder (mode 0700) under $TMPDIR or /tmp. Entries
  /// with an absolute path or a ".." component are refused, so an archive cannot write outside
  /// the folder. Throws plant::PlantError naming the file and the entry.
  explicit UnpackedFmu(const std::filesystem::path& fmu_path);
  ~UnpackedFmu();
  UnpackedFmu(const UnpackedFmu&) = delete;
  UnpackedFmu& operator=(const UnpackedFmu&) = delete;

  [[nodiscard]] const std::filesystem::path& dir() const noexcept { return dir_; }

 private:
  std::filesystem::path dir_;
};

/// True when a zip entry name stays inside the folder it is unpacked into: relative, no ".."
/// component (either slash counts: archives made on Windows use backslashes).
[[nodiscard]] bool IsSafeEntryName(std::string_view name) noexcept;

}  // namespace hiltwin::fmi
