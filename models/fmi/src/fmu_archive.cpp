// Unpacking with libzip. The folder is made by mkdtemp so no other user can plant files in it
// before dlopen reads the binary from it. Only what a run needs is unpacked, within the caps of
// FmuUnpackLimits, so an archive cannot fill $TMPDIR (a 1 MB FMU unpacked a 1 GiB entry).
#include "fmu_archive.h"

#include <fcntl.h>
#include <unistd.h>
#include <zip.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "hiltwin/plant/plant.h"

namespace hiltwin::fmi {
namespace {

using plant::PlantError;

struct ZipCloser {
  void operator()(zip_t* archive) const noexcept { zip_discard(archive); }
};
using ZipPtr = std::unique_ptr<zip_t, ZipCloser>;

struct ZipFileCloser {
  void operator()(zip_file_t* file) const noexcept { zip_fclose(file); }
};

struct FdCloser {
  explicit FdCloser(int descriptor) noexcept : fd(descriptor) {}
  FdCloser(const FdCloser&) = delete;
  FdCloser& operator=(const FdCloser&) = delete;
  ~FdCloser() { ::close(fd); }
  int fd;
};

// strerror's thread-safe spelling.
std::string ErrnoText() { return std::generic_category().message(errno); }

ZipPtr OpenZip(const std::filesystem::path& fmu_path) {
  int code = 0;
  zip_t* archive = zip_open(fmu_path.c_str(), ZIP_RDONLY, &code);
  if (archive == nullptr) {
    zip_error_t error;
    zip_error_init_with_code(&error, code);
    const std::string why = zip_error_strerror(&error);
    zip_error_fini(&error);
    throw PlantError(fmu_path.string() + ": not a readable FMU (an FMU is a zip archive; " +
                     "libzip says: " + why +
                     "): check the path, or export the FMU again from the modelling tool");
  }
  return ZipPtr(archive);
}

std::filesystem::path MakePrivateDir() {
  // Opening happens before any helper thread runs, so nothing sets the environment meanwhile.
  const char* tmp = std::getenv("TMPDIR");  // NOLINT(concurrency-mt-unsafe)
  std::string pattern =
      std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/hiltwin-fmu-XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (mkdtemp(buffer.data()) == nullptr) {
    throw PlantError("cannot make a folder to unpack the FMU into (" + pattern +
                     "): " + ErrnoText() + ": set TMPDIR to a writable folder");
  }
  return {buffer.data()};
}

// The bytes an archive may still unpack, counted before each entry (its declared size) and
// while it is written (what it really holds: a header may lie).
class UnpackBudget {
 public:
  explicit UnpackBudget(std::uint64_t max_bytes) : max_bytes_(max_bytes) {}

  void Reserve(std::uint64_t declared, const std::string& where) const {
    if (declared <= max_bytes_ - used_) return;
    throw PlantError(where + " (" + std::to_string(declared) + " bytes) would unpack more than " +
                     std::to_string(max_bytes_) + " bytes in all (with the " +
                     std::to_string(used_) + " bytes before it), " + kWhatIsUnpacked);
  }

  void Take(std::uint64_t bytes, const std::string& where) {
    if (bytes > max_bytes_ - used_) {
      throw PlantError(where + " unpacks to more than its declared size and past " +
                       std::to_string(max_bytes_) + " bytes in all, " + kWhatIsUnpacked);
    }
    used_ += bytes;
  }

 private:
  static constexpr const char* kWhatIsUnpacked =
      "the most hiltwin unpacks from an FMU (of modelDescription.xml, "
      "binaries/" HILTWIN_FMU_PLATFORM "/ and resources/): export the FMU with smaller "
      "resources, or check that it is one";
  std::uint64_t max_bytes_;
  std::uint64_t used_ = 0;
};

std::uint64_t DeclaredSize(zip_t* archive, zip_uint64_t index) {
  zip_stat_t stat;
  zip_stat_init(&stat);
  if (zip_stat_index(archive, index, 0, &stat) != 0 || (stat.valid & ZIP_STAT_SIZE) == 0) return 0;
  return stat.size;
}

// write(2) until all is written; false with errno set when it cannot (a full disk).
bool WriteAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t wrote = ::write(fd, data, size);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      if (wrote == 0) errno = ENOSPC;
      return false;
    }
    data += wrote;
    size -= static_cast<std::size_t>(wrote);
  }
  return true;
}

void WriteEntry(zip_t* archive, zip_uint64_t index, const std::filesystem::path& target,
                const std::string& where, UnpackBudget& budget) {
  budget.Reserve(DeclaredSize(archive, index), where);
  std::unique_ptr<zip_file_t, ZipFileCloser> in(zip_fopen_index(archive, index, 0));
  if (!in) {
    throw PlantError(where + ": cannot read the entry (libzip says: " + zip_strerror(archive) +
                     "): the FMU is damaged; export it again");
  }
  // O_EXCL | O_NOFOLLOW: a second entry of the same name or a link never redirects a write.
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw PlantError(where + ": cannot unpack to " + target.string() + ": " + ErrnoText() +
                     " (is the entry in the archive twice?)");
  }
  const FdCloser closer{fd};
  std::array<char, 65536> buffer{};
  for (;;) {
    const zip_int64_t got = zip_fread(in.get(), buffer.data(), buffer.size());
    if (got == 0) return;
    if (got < 0) {
      // libzip's own reason: "CRC error", "Zlib error: data error", "Premature end of file".
      throw PlantError(where + ": cannot unpack it (libzip says: " +
                       zip_error_strerror(zip_file_get_error(in.get())) +
                       "): the FMU is damaged; export it again");
    }
    budget.Take(static_cast<std::uint64_t>(got), where);
    if (!WriteAll(fd, buffer.data(), static_cast<std::size_t>(got))) {
      throw PlantError(where + ": cannot write " + target.string() + ": " + ErrnoText() +
                       ": free space in " + target.parent_path().string());
    }
  }
}

// What running the FMU needs: its description, this platform's binaries and its resources.
bool IsNeeded(std::string_view name) {
  constexpr std::string_view kBinaries = "binaries/" HILTWIN_FMU_PLATFORM "/";
  return name == "modelDescription.xml" || name.starts_with(kBinaries) ||
         name.starts_with("resources/");
}

// "linux64" for "binaries/linux64/x.so", "" for a name outside binaries/<platform>/.
std::string_view BinaryPlatform(std::string_view name) {
  constexpr std::string_view kBinaries = "binaries/";
  if (!name.starts_with(kBinaries)) return {};
  name.remove_prefix(kBinaries.size());
  const std::size_t slash = name.find('/');
  return slash == std::string_view::npos ? std::string_view{} : name.substr(0, slash);
}

void CheckEntryCount(zip_t* archive, const std::filesystem::path& fmu_path,
                     const FmuUnpackLimits& limits) {
  const zip_int64_t count = zip_get_num_entries(archive, 0);
  if (count >= 0 && static_cast<std::uint64_t>(count) <= limits.max_entries) return;
  throw PlantError(fmu_path.string() + ": the archive has " + std::to_string(count) +
                   " entries, more than the " + std::to_string(limits.max_entries) +
                   " hiltwin opens in an FMU: export the FMU again without the extra files "
                   "(sources, documentation), or check that it is one");
}

// Unpacks the needed entries; returns the platforms the archive has binaries for.
std::string UnpackNeeded(zip_t* archive, const std::filesystem::path& fmu_path,
                         const std::filesystem::path& dir, const FmuUnpackLimits& limits) {
  CheckEntryCount(archive, fmu_path, limits);
  UnpackBudget budget(limits.max_bytes);
  std::set<std::string, std::less<>> platforms;
  const zip_int64_t count = zip_get_num_entries(archive, 0);
  for (zip_int64_t i = 0; i < count; ++i) {
    const auto index = static_cast<zip_uint64_t>(i);
    const char* raw_name = zip_get_name(archive, index, ZIP_FL_ENC_GUESS);
    const std::string name = raw_name != nullptr ? raw_name : "";
    const std::string where = fmu_path.string() + ": entry \"" + name + "\"";
    if (!IsSafeEntryName(name)) {
      throw PlantError(where + " has an absolute path or a \"..\" component and would unpack " +
                       "outside the FMU's folder: refused; this is not a well-formed FMU");
    }
    if (!BinaryPlatform(name).empty()) platforms.emplace(BinaryPlatform(name));
    if (!IsNeeded(name)) continue;
    const std::filesystem::path target = dir / name;
    const bool folder = name.back() == '/';
    std::error_code error;
    std::filesystem::create_directories(folder ? target : target.parent_path(), error);
    if (error) {
      throw PlantError(where + ": cannot make " + target.string() + ": " + error.message());
    }
    if (!folder) WriteEntry(archive, index, target, where, budget);
  }
  std::string list;
  for (const std::string& platform : platforms) list += (list.empty() ? "" : ", ") + platform;
  return list.empty() ? "none" : list;
}

}  // namespace

bool IsSafeEntryName(std::string_view name) noexcept {
  if (name.empty() || name.front() == '/' || name.front() == '\\' ||
      (name.size() > 1 && name[1] == ':')) {  // "C:..." from an archiver on Windows
    return false;
  }
  std::size_t start = 0;
  while (start <= name.size()) {
    std::size_t end = name.find_first_of("/\\", start);
    if (end == std::string_view::npos) {
      end = name.size();
    }
    if (name.substr(start, end - start) == "..") {
      return false;
    }
    start = end + 1;
  }
  return true;
}

UnpackedFmu::UnpackedFmu(const std::filesystem::path& fmu_path, const FmuUnpackLimits& limits) {
  const ZipPtr archive = OpenZip(fmu_path);
  dir_ = MakePrivateDir();
  try {
    platforms_ = UnpackNeeded(archive.get(), fmu_path, dir_, limits);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
    throw;
  }
}

UnpackedFmu::~UnpackedFmu() {
  std::error_code ignored;  // a destructor cannot report; a leftover folder is only clutter
  std::filesystem::remove_all(dir_, ignored);
}

}  // namespace hiltwin::fmi
