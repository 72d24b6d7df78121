// ReadTrace: what `hiltwin trace --analyze PATH` reads, chosen by what PATH is.
#include "hiltwin/traces/trace_readers.h"

#include <filesystem>
#include <string>
#include <system_error>

namespace hiltwin::analysis {

const char* ToString(TraceSource source) noexcept {
  switch (source) {
    case TraceSource::kLttng:
      return "lttng";
    case TraceSource::kTimingLog:
      return "timing_log";
  }
  return "unknown";
}

TimingTrace ReadTrace(const std::string& path, int pid) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::is_directory(status)) return ReadCtfTrace(path, pid);
  if (fs::is_regular_file(status)) {
    if (pid > 0) {
      throw TraceReadError(path +
                           ": a timing log holds one process's cycles; a process id "
                           "only chooses among the processes of an LTTng trace folder");
    }
    return ReadTimingLog(path);
  }
  const std::string what = fs::exists(status) ? "is neither a folder nor a regular file"
                           : error && error != std::errc::no_such_file_or_directory
                               ? "cannot be examined: " + error.message()
                               : "does not exist";
  throw TraceReadError(path + " " + what +
                       "; pass an LTTng trace folder (`hiltwin trace --output DIR`) or a timing "
                       "log file (`hiltwin run --timing-log FILE`)");
}

}  // namespace hiltwin::analysis
