#pragma once
/// `hiltwin trace`: the twin run exactly as `hiltwin run` runs it (twin_run.h), inside an LTTng
/// recording (and, with --kernel, a recording of the kernel's scheduler events), then the jitter
/// report of that recording; or (--analyze) the report of a recording made earlier, by us or by
/// hand, or of a timing log.

#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/runs/output_files.h"
#include "hiltwin/runs/twin_run.h"
#include "hiltwin/runtime/run_report.h"

namespace hiltwin::app {

struct TraceOptions {
  TwinRunOptions run;
  std::string output_dir;    ///< where the trace and the report go
  bool kernel = false;       ///< also record the kernel's scheduler and interrupt events
  std::string analyze_path;  ///< set: analyse this trace folder or timing log, run nothing
  int analyze_pid = 0;       ///< with analyze_path: the process of the trace to report on
};

/// The files trace writes into its folder `dir` (--output), as outputs for CheckFilesDistinct
/// beside the run's: the run report, the jitter report's text, JSON, HTML and pictures, the
/// Perfetto trace. None without a folder.
[[nodiscard]] std::vector<NamedFile> TraceOutputFiles(const std::string& dir);

/// Records, runs, analyses; returns the run's exit code (or 5 when the recording or its
/// analysis failed after a run that was otherwise fine). Throws CommandError before the run.
int TraceTwin(const TraceOptions& o);

/// Analyses o.analyze_path into o.output_dir (default: the trace folder itself, or
/// `<log>.jitter/` beside a timing log). Throws CommandError (exit 2) for unusable input.
int AnalyzeTrace(const TraceOptions& o);

/// Where the trace's own report disagrees with the run's: cycles, misses, and every percentile
/// beyond the histogram's resolution. Empty when they agree.
[[nodiscard]] std::vector<std::string> CompareWithRunReport(const runtime::RunReport& run,
                                                            const analysis::JitterReport& trace);

}  // namespace hiltwin::app
