#pragma once
/// The files a command reads and writes, kept apart and written safely: one check, made by
/// every command's flags -> configuration step before anything is created, that no output
/// names the file of an input or of another output (CheckFilesDistinct); and the report file,
/// written whole at the end or not at all (ReportFile), so a failed run never loses the
/// previous run's report and a full disk never leaves half a report.

#include <span>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/kernel_glue/output_file.h"

namespace hiltwin::app {

/// One file a command reads or writes, as the user named it.
struct NamedFile {
  std::string flag;      ///< who named it, for messages: "--log", "--log-dir (the twin's log)"
  std::string path;      ///< as given; empty: not given (skipped)
  bool written = false;  ///< an output; otherwise an input the command reads
};

/// Refuses (CommandError kUsage, exit 2) any two of `files` that name the same file when at
/// least one of them is written: an output would overwrite an input (or delete it, a report
/// created before the inputs are read) or two outputs would mix in one file. Two inputs may
/// share a file (assess's --sim and --exp from one log). The same file: the same device and
/// inode for files that exist (so hard links, symbolic links and other spellings are seen),
/// the same absolute, normalised path (symbolic links in its folders resolved) for files that
/// do not exist yet. Existing files that are not regular (/dev/null, a FIFO) hold nothing to
/// clobber and are not compared. The message names both flags, both paths and what to do.
void CheckFilesDistinct(const std::vector<NamedFile>& files);

/// `text` given to a profile flag (--input, --setpoint) as an input file: no file (an empty
/// path) when it is one of `builtin_names`, which name profiles built into the program.
[[nodiscard]] NamedFile ProfileFile(std::string flag, const std::string& text,
                                    std::span<const std::string_view> builtin_names);

/// The --report file (or another whole-file report: `flag` names it), written through
/// kernel_glue::ReplacementFile: the path is checked when this is made, before the run (a
/// link, a folder, a missing folder: exit 2), and the report replaces an earlier file only once
/// it is whole on the disk. A command that ends without writing it (the wrong FPGA image at
/// INIT, a log that cannot be created) leaves the earlier file as it was and no new one.
class ReportFile {
 public:
  ReportFile() = default;  ///< no --report
  explicit ReportFile(const std::string& path, const std::string& flag = "--report");

  /// A report was asked for and is not written yet.
  [[nodiscard]] bool wanted() const noexcept { return file_.is_open(); }
  /// Writes `text` whole; CommandError (exit 5) naming the path and the reason when it cannot.
  void Write(const std::string& text);
  /// Writes `text` at the end of a command whose summary is printed: when it cannot, says so
  /// on stderr ("hiltwin COMMAND: --report PATH: cannot write ... (REASON); ...") and returns
  /// `exit_code` made at least as bad as 5 (an unwritable log's code); else `exit_code`.
  [[nodiscard]] int WriteAtEnd(const std::string& text, const char* command, int exit_code);

 private:
  kernel_glue::ReplacementFile file_;
  std::string flag_;
};

/// A run report another process wrote (a `hil` side's, a campaign scenario's); nullopt when
/// there is none or it is not whole JSON (a process that died mid-write).
[[nodiscard]] std::optional<nlohmann::ordered_json> ReadReportFile(const std::filesystem::path& path);

/// The folder a command keeps its children's files in: the one the user named (made when
/// missing; one that cannot be made is exit 2 naming `flag`), or, when none is named, a fresh
/// temporary one, TMPDIR/PREFIX-XXXXXX (exit 5 when it cannot be made), removed with this
/// object. `hil` keeps its sides' reports, logs and output there, `test` its scenarios'.
class WorkFolder {
 public:
  WorkFolder(const std::string& named_path, const std::string& flag, const std::string& prefix);
  ~WorkFolder();
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

 private:
  std::filesystem::path path_;
  bool temporary_ = false;
};

}  // namespace hiltwin::app
