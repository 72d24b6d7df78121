// An FMU's zip archive (models/fmi/src/fmu_archive.h): UnpackedFmu unpacks it into a private folder
// and documents plant::PlantError naming the file and the entry. The input is written to a
// scratch .fmu; TMPDIR points the unpacking into this process's scratch folder. Checked: every
// file it unpacked lies inside its folder (no entry escapes), and the folder is gone after.
// libFuzzer's -max_len (scripts/fuzz.sh) bounds the input, and with it what deflate can
// expand to.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fmu_archive.h"
#include "fuzz_util.h"
#include "hiltwin/plant/plant.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "FINDING: %s\n", what);
    std::abort();
  }
}

void CheckInside(const std::filesystem::path& dir) {
  const std::string root = std::filesystem::weakly_canonical(dir).string() + "/";
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    Require(!entry.is_symlink(), "an unpacked entry is a symbolic link");
    const std::string path = std::filesystem::weakly_canonical(entry.path()).string();
    Require(path.rfind(root, 0) == 0, "an unpacked entry lies outside the FMU's folder");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path& scratch = hiltwin::fuzz::ScratchDir();
  static const bool tmpdir_set = [&scratch] {
    std::filesystem::create_directories(scratch / "unpack");
    return ::setenv("TMPDIR", (scratch / "unpack").c_str(), 1) == 0;
  }();
  Require(tmpdir_set, "cannot set TMPDIR");
  const auto path = hiltwin::fuzz::WriteScratch("input.fmu", data, size);
  std::filesystem::path unpacked_dir;
  try {
    const hiltwin::fmi::UnpackedFmu fmu(path, hiltwin::fmi::FmuUnpackLimits{});
    unpacked_dir = fmu.dir();
    CheckInside(unpacked_dir);
  } catch (const hiltwin::plant::PlantError&) {
  }
  HILTWIN_FUZZ_UNDOCUMENTED("UnpackedFmu")
  Require(std::filesystem::is_empty(scratch / "unpack"), "UnpackedFmu left its folder behind");
  return 0;
}
