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

namespace {

/// What is wrong with an existing `path` that a replacement would overwrite; 0 when nothing
/// is (or when it does not exist yet: the temporary file's open then names the folder).
int ReplacementProblem(const std::string& path, const struct stat& status) {
  if (S_ISLNK(status.st_mode)) return ELOOP;
  if (S_ISDIR(status.st_mode)) return EISDIR;
  // A file the user may not write is not replaced behind its back (the folder may allow it).
  return ::access(path.c_str(), W_OK) == 0 ? 0 : errno;
}

/// The temporary file beside `path`: created, never an old file (O_EXCL); a stale one of a
/// killed process with the same pid is skipped.
int OpenTemporaryBeside(const std::string& path, const std::string& name, std::string& temporary) {
  const std::filesystem::path given(path);
  const std::string stem = "." + given.filename().string() + ".hiltwin-" +
                           std::to_string(::getpid()) + "-";
  for (int attempt = 0;; ++attempt) {
    temporary = (given.parent_path() / (stem + std::to_string(attempt))).string();
    int fd = -1;
    do {
      fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    } while (fd < 0 && errno == EINTR);
    if (fd >= 0) return fd;
    const int error_number = errno;
    if (error_number != EEXIST || attempt == 99) {
      temporary.clear();
      throw OutputFileError(name, path, Problem(path, error_number), error_number);
    }
  }
}

/// Writes all of `text` to `fd`; 0 or the errno of the write that failed.
int WriteAll(int fd, const std::string& text) noexcept {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno != EINTR) {
      return errno;
    }
  }
  return 0;
}

}  // namespace

ReplacementFile::ReplacementFile(std::string path, const std::string& name)
    : path_(std::move(path)) {
  struct stat status {};
  const bool exists = !path_.empty() && ::lstat(path_.c_str(), &status) == 0;
  const bool in_place = path_.empty() || (exists && !S_ISREG(status.st_mode) &&
                                          !S_ISLNK(status.st_mode) && !S_ISDIR(status.st_mode));
  if (in_place) {  // a device or a FIFO (an empty path: refused there, with its message)
    fd_ = OpenOutputFile(path_, name);
    return;
  }
  if (exists) {
    if (const int error_number = ReplacementProblem(path_, status); error_number != 0) {
      throw OutputFileError(name, path_, Problem(path_, error_number), error_number);
    }
  }
  fd_ = OpenTemporaryBeside(path_, name, temporary_);
}

ReplacementFile::ReplacementFile(ReplacementFile&& other) noexcept
    : path_(std::move(other.path_)),
      temporary_(std::move(other.temporary_)),
      fd_(std::exchange(other.fd_, -1)) {
  other.temporary_.clear();
}

ReplacementFile::~ReplacementFile() { Discard(); }

void ReplacementFile::Discard() noexcept {
  if (fd_ < 0) return;
  // Removed only while the name still holds the file this made (nobody replaced it meanwhile).
  struct stat ours {};
  struct stat named {};
  if (!temporary_.empty() && ::fstat(fd_, &ours) == 0 &&
      ::lstat(temporary_.c_str(), &named) == 0 && ours.st_dev == named.st_dev &&
      ours.st_ino == named.st_ino) {
    ::unlink(temporary_.c_str());
  }
  ::close(std::exchange(fd_, -1));
}

int ReplacementFile::Commit(const std::string& text) noexcept {
  if (fd_ < 0) return EBADF;
  int error_number = WriteAll(fd_, text);
  // On the disk before it replaces the old file, so a crash leaves one or the other whole.
  if (error_number == 0 && !temporary_.empty() && ::fsync(fd_) != 0) error_number = errno;
  if (error_number != 0) {
    Discard();
    return error_number;
  }
  if (::close(std::exchange(fd_, -1)) != 0) error_number = errno;
  if (error_number == 0 && !temporary_.empty() &&
      ::rename(temporary_.c_str(), path_.c_str()) != 0) {
    error_number = errno;
  }
  if (error_number != 0 && !temporary_.empty()) ::unlink(temporary_.c_str());
  return error_number;
}

}  // namespace hiltwin::kernel_glue
