// Unpacking with libzip. The folder is made by mkdtemp so no other user can plant files in it
// before dlopen reads the binary from it.
#include "fmu_archive.h"

#include <fcntl.h>
#include <unistd.h>
#include <zip.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <memory>
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

void WriteEntry(zip_t* archive, zip_uint64_t index, const std::filesystem::path& target,
                const std::string& where) {
  std::unique_ptr<zip_file_t, ZipFileCloser> in(zip_fopen_index(archive, index, 0));
  if (!in) {
    throw PlantError(where + ": cannot read the entry (" + zip_strerror(archive) +
                     "): the FMU is damaged; export it again");
  }
  // O_EXCL | O_NOFOLLOW: a second entry of the same name or a link never redirects a write.
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw PlantError(where + ": cannot unpack to " + target.string() + ": " + ErrnoText() +
                     " (is the entry in the archive twice?)");
  }
  std::array<char, 65536> buffer{};
  bool ok = true;
  for (;;) {
    const zip_int64_t got = zip_fread(in.get(), buffer.data(), buffer.size());
    if (got <= 0) {
      ok = got == 0;
      break;
    }
    if (::write(fd, buffer.data(), static_cast<std::size_t>(got)) != got) {
      ok = false;
      break;
    }
  }
  ::close(fd);
  if (!ok) {
    throw PlantError(where +
                     ": unpacking failed (damaged entry or disk full): export the FMU "
                     "again or free space in " +
                     target.parent_path().string());
  }
}

void UnpackAll(zip_t* archive, const std::filesystem::path& fmu_path,
               const std::filesystem::path& dir) {
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
    const std::filesystem::path target = dir / name;
    std::error_code error;
    if (name.back() == '/') {
      std::filesystem::create_directories(target, error);
    } else {
      std::filesystem::create_directories(target.parent_path(), error);
      if (!error) {
        WriteEntry(archive, index, target, where);
      }
    }
    if (error) {
      throw PlantError(where + ": cannot make " + target.string() + ": " + error.message());
    }
  }
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

UnpackedFmu::UnpackedFmu(const std::filesystem::path& fmu_path) {
  const ZipPtr archive = OpenZip(fmu_path);
  dir_ = MakePrivateDir();
  try {
    UnpackAll(archive.get(), fmu_path, dir_);
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
