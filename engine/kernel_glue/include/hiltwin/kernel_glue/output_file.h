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

}  // namespace hiltwin::kernel_glue
