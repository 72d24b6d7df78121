#include "hiltwin/kernel_glue/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>

namespace hiltwin::kernel_glue {
namespace {

std::string StrError(int error_number) {
  char buffer[256];
  return strerror_r(error_number, buffer, sizeof buffer);  // GNU form: may not use the buffer
}

// The link's text, or "?" when it cannot be read (it was removed meanwhile).
std::string LinkTarget(const std::string& path) {
  std::string target(4096, '\0');
  const ssize_t length = ::readlink(path.c_str(), target.data(), target.size());
  if (length < 0) return "?";
  target.resize(static_cast<std::size_t>(length));
  return target;
}

bool IsSymbolicLink(const std::string& path) {
  struct stat status {};
  return ::lstat(path.c_str(), &status) == 0 && S_ISLNK(status.st_mode);
}

std::string FolderOf(const std::string& path) {
  const std::string folder = std::filesystem::path(path).parent_path().string();
  return folder.empty() ? "." : folder;
}

// What an open failure means for someone who typed the path, and what to do about it.
std::string Problem(const std::string& path, int error_number) {
  switch (error_number) {
    case ELOOP:
    case EMLINK:  // what some systems return for O_NOFOLLOW on a link
      if (IsSymbolicLink(path)) {
        return " is a symbolic link (to " + LinkTarget(path) +
               "); hiltwin does not write through links: name the real file";
      }
      break;
    case ENOENT:
      return ": the folder '" + FolderOf(path) + "' does not exist; create it first";
    case ENOTDIR:
      return ": a part of the folder path '" + FolderOf(path) +
             "' is not a folder; check the path";
    case EISDIR:
      return " is a folder; name a file inside it";
    case EACCES:
    case EPERM:
      return ": permission denied (" + StrError(error_number) +
             "); choose a file in a folder you can write to";
    case EROFS:
      return ": the file system is read-only; write to another folder";
    default:
      break;
  }
  return ": cannot create the file (" + StrError(error_number) + ")";
}

}  // namespace

OutputFileError::OutputFileError(const std::string& name, std::string path, std::string problem,
                                 int error_number)
    : std::runtime_error(name + " " + path + problem),
      path_(std::move(path)),
      problem_(std::move(problem)),
      error_number_(error_number) {}

int OpenOutputFile(const std::string& path, const std::string& name) {
  if (path.empty()) {
    throw OutputFileError(name, path, "(empty): name a file, e.g. run.csv", ENOENT);
  }
  int fd = -1;
  do {
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
  } while (fd < 0 && errno == EINTR);  // a FIFO's open may be interrupted while it waits
  if (fd < 0) {
    const int error_number = errno;
    throw OutputFileError(name, path, Problem(path, error_number), error_number);
  }
  return fd;
}

}  // namespace hiltwin::kernel_glue
