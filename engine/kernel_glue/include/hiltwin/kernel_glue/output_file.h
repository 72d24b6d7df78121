#pragma once
/// Opening a file the user named on the command line for writing (a log, a report, a plot),
/// without surprises: a final path component that is a symbolic link is refused instead of
/// followed (the link could point anywhere, e.g. at a file the user did not mean to
/// overwrite), and the usual failures (missing folder, a folder named instead of a file, no
/// permission) come back as one clear sentence that names the flag, the path and the fix.

#include <stdexcept>
#include <string>

namespace hiltwin::kernel_glue {

/// A user-named output file that cannot be opened. what() reads
/// "<name> <path><problem>", e.g. "--log run.csv is a symbolic link (to /etc/passwd);
/// hiltwin does not write through links: name the real file".
class OutputFileError : public std::runtime_error {
 public:
  OutputFileError(const std::string& name, std::string path, std::string problem,
                  int error_number);
  /// The path as given.
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  /// What is wrong and what to do, starting with " is ..." or ": ...".
  [[nodiscard]] const std::string& problem() const noexcept { return problem_; }
  /// The errno of the failed open.
  [[nodiscard]] int error_number() const noexcept { return error_number_; }
  /// The message with another name for the file, e.g. the flag that named it ("--log").
  [[nodiscard]] std::string MessageFor(const std::string& name) const {
    return name + " " + path_ + problem_;
  }

 private:
  std::string path_;
  std::string problem_;
  int error_number_;
};

/// Opens `path` write-only, created (mode 0644 less the umask) or truncated, close-on-exec,
/// and returns the descriptor (the caller closes it). A final component that is a symbolic
/// link is refused (O_NOFOLLOW; the link and its target stay untouched); links in the folders
/// above it are followed, since the user named those folders. `name` says who named the path
/// in messages ("--log"). Throws OutputFileError.
[[nodiscard]] int OpenOutputFile(const std::string& path, const std::string& name);

/// An output file written whole or not at all (a report): the text goes to a new file beside
/// `path` (same folder, hidden name `.<file>.hiltwin-<pid>-<n>`, so one file system and an
/// atomic rename(2)), which replaces `path` only once it is whole and on the disk. A write that
/// fails (a full disk, a size limit) leaves `path` as it was, a previous run's file included;
/// only the temporary file is removed. `path` is checked when this is made, so a path that
/// cannot be written fails before the work whose result it is meant to hold: a final symbolic
/// link, a folder, a missing folder and a file the user may not write are refused as
/// OpenOutputFile refuses them (OutputFileError naming `path`). An existing `path` that is not a
/// regular file (a device such as /dev/null, a FIFO) is opened in place instead: it holds
/// nothing to keep, and a rename would replace the device node.
class ReplacementFile {
 public:
  ReplacementFile() = default;  ///< nothing to write
  /// `name` says who named `path` in messages ("--report"). Throws OutputFileError.
  ReplacementFile(std::string path, const std::string& name);
  /// Not committed: removes the temporary file; `path` stays as it was.
  ~ReplacementFile();
  ReplacementFile(ReplacementFile&& other) noexcept;
  ReplacementFile& operator=(ReplacementFile&&) = delete;
  ReplacementFile(const ReplacementFile&) = delete;
  ReplacementFile& operator=(const ReplacementFile&) = delete;

  /// A file is open to be written (not default-made, not committed yet).
  [[nodiscard]] bool is_open() const noexcept { return fd_ >= 0; }
  /// The path as given.
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  /// The temporary file's name; empty when `path` is written in place.
  [[nodiscard]] const std::string& temporary_path() const noexcept { return temporary_; }

  /// Writes `text`, flushes it to the disk (fsync) and renames it over `path`. Returns 0, or
  /// the errno of the step that failed, after removing the temporary file. Once only.
  [[nodiscard]] int Commit(const std::string& text) noexcept;

 private:
  void Discard() noexcept;

  std::string path_;
  std::string temporary_;
  int fd_ = -1;
};

}  // namespace hiltwin::kernel_glue
