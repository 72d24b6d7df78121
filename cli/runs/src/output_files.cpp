// The files a command reads and writes (output_files.h): kept apart, and reports written whole.
#include "hiltwin/runs/output_files.h"

#include <stdlib.h>

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <system_error>
#include <utility>

#include "hiltwin/runs/command.h"
#include "hiltwin/runs/hil_report.h"

namespace hiltwin::app {
namespace {

namespace fs = std::filesystem;

/// What makes two names one file: the inode of an existing regular file, or the normalised
/// absolute path of one that does not exist yet.
struct FileIdentity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string normal_path;

  [[nodiscard]] bool operator==(const FileIdentity& other) const {
    if (exists != other.exists) return false;
    return exists ? device == other.device && inode == other.inode
                  : normal_path == other.normal_path;
  }
};

/// Empty for a file that holds nothing to clobber (a device, a FIFO, a folder).
std::optional<FileIdentity> IdentityOf(const std::string& path) {
  FileIdentity identity;
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0) {  // through links: a link to the input is the input
    if (!S_ISREG(status.st_mode)) return std::nullopt;
    identity.exists = true;
    identity.device = status.st_dev;
    identity.inode = status.st_ino;
    return identity;
  }
  std::error_code ignored;
  fs::path normal = fs::weakly_canonical(fs::absolute(path, ignored), ignored);
  identity.normal_path = normal.lexically_normal().string();
  return identity;
}

std::string Named(const NamedFile& file) { return file.flag + " " + file.path; }

/// "--log x.csv and --report x.csv name the same file: ..." with what to do.
[[noreturn]] void RefuseSameFile(const NamedFile& a, const NamedFile& b) {
  if (a.written && b.written) {
    ThrowUsage(Named(a) + " and " + Named(b) +
               " name the same file: each output would overwrite the other; give each its own "
               "file");
  }
  const NamedFile& output = a.written ? a : b;
  const NamedFile& input = a.written ? b : a;
  ThrowUsage(Named(output) + " and " + Named(input) + " name the same file: " + output.flag +
             " would overwrite the file " + input.flag + " reads; give " + output.flag +
             " another file");
}

/// The report's file, checked now (a link or a missing folder: exit 2); none without a path.
kernel_glue::ReplacementFile OpenReport(const std::string& path, const std::string& flag) {
  if (path.empty()) return {};
  try {
    return {path, flag};
  } catch (const kernel_glue::OutputFileError& e) {
    ThrowUsage(e.what());
  }
}

}  // namespace

void CheckFilesDistinct(const std::vector<NamedFile>& files) {
  std::vector<std::pair<const NamedFile*, FileIdentity>> seen;
  for (const NamedFile& file : files) {
    if (file.path.empty()) continue;
    const std::optional<FileIdentity> identity = IdentityOf(file.path);
    if (!identity) continue;
    for (const auto& [earlier, earlier_identity] : seen) {
      if ((file.written || earlier->written) && earlier_identity == *identity) {
        RefuseSameFile(*earlier, file);
      }
    }
    seen.emplace_back(&file, *identity);
  }
}

NamedFile ProfileFile(std::string flag, const std::string& text,
                      std::span<const std::string_view> builtin_names) {
  const bool builtin =
      std::find(builtin_names.begin(), builtin_names.end(), text) != builtin_names.end();
  return {std::move(flag), builtin ? std::string() : text, false};
}

ReportFile::ReportFile(const std::string& path, const std::string& flag)
    : file_(OpenReport(path, flag)), flag_(flag) {}

void ReportFile::Write(const std::string& text) {
  if (!file_.is_open()) return;
  const int error_number = file_.Commit(text);
  if (error_number != 0) {
    throw CommandError(ExitCode::kIo, flag_ + " " + file_.path() + ": cannot write the report (" +
                                          std::strerror(error_number) +
                                          "); check the disk has space and the folder is "
                                          "writable");
  }
}

int ReportFile::WriteAtEnd(const std::string& text, const char* command, int exit_code) {
  try {
    Write(text);
  } catch (const CommandError& e) {
    std::fprintf(stderr, "hiltwin %s: %s\n", command, e.what());
    return WorseExitCode(exit_code, static_cast<int>(e.code()));
  }
  return exit_code;
}

std::optional<nlohmann::ordered_json> ReadReportFile(const std::filesystem::path& path) {
  std::ifstream file(path);
  if (!file) return std::nullopt;
  try {
    return nlohmann::ordered_json::parse(file);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

WorkFolder::WorkFolder(const std::string& named_path, const std::string& flag,
                       const std::string& prefix) {
  namespace fs = std::filesystem;
  if (!named_path.empty()) {
    std::error_code error;
    path_ = fs::absolute(named_path);
    fs::create_directories(path_, error);
    if (error) ThrowUsage(flag + " " + named_path + ": " + error.message());
    return;
  }
  std::string pattern = (fs::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw CommandError(ExitCode::kIo,
                       "cannot create a temporary folder in " + fs::temp_directory_path().string());
  }
  path_ = pattern;
  temporary_ = true;
}

WorkFolder::~WorkFolder() {
  std::error_code ignored;
  if (temporary_) std::filesystem::remove_all(path_, ignored);
}

}  // namespace hiltwin::app
