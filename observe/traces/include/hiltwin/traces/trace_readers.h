#pragma once
/// Reading a run's loop timing into a TimingTrace: an LTTng CTF trace of the `hiltwin`
/// provider (through libbabeltrace2's graph API: the source.ctf.fs component and a sink of our
/// own; never by parsing babeltrace2's text) or a timing log (tracing/timing_log_format.h).
/// Every reader throws TraceReadError naming the file and the place for input it cannot use:
/// a folder with no trace, a truncated CTF stream, a torn row, an unknown code.

#include <string>

#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis {

/// Reads the CTF trace under `dir` (searched recursively for CTF `metadata`: `lttng create
/// --output=DIR` puts it in DIR/ust/uid/<uid>/64-bit/). Several hiltwin processes in one trace:
/// the first one to start its loop (other_processes counts the rest), or process `pid` when
/// it is given (`hiltwin trace` knows its own).
[[nodiscard]] TimingTrace ReadCtfTrace(const std::string& dir, int pid = 0);

/// Reads a timing log written by `hiltwin run --timing-log FILE`.
[[nodiscard]] TimingTrace ReadTimingLog(const std::string& path);

/// A folder: ReadCtfTrace; a file: ReadTimingLog; anything else: TraceReadError saying what
/// `hiltwin trace --analyze` accepts.
/// `pid` > 0 picks that process of a trace folder (refused for a timing log).
[[nodiscard]] TimingTrace ReadTrace(const std::string& path, int pid = 0);

}  // namespace hiltwin::analysis
