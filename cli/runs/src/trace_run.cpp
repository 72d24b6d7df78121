// `hiltwin trace` (trace_run.h): capture -> the twin run of `hiltwin run` -> stop the capture ->
// read the trace -> the jitter report and its outputs -> agreement with the run's own report.
#include "hiltwin/runs/trace_run.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "hiltwin/jitter/jitter_outputs.h"
#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/report_kit/gnuplot.h"  // PlotError
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/hil_report.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "hiltwin/trace_capture/kernel_recorder.h"
#include "hiltwin/trace_capture/lttng_session.h"
#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/trace_readers.h"
#include "hiltwin/tracing/csv.h"

namespace hiltwin::app {
namespace {

namespace fs = std::filesystem;

/// The files trace writes into its folder: its own, then the jitter module's (html, Perfetto,
/// the pictures), named here too so that no run output is pointed at one of them.
constexpr const char* kRunReportName = "run_report.json";
constexpr const char* kTextReportName = "jitter_report.txt";
constexpr const char* kJsonReportName = "jitter_report.json";
constexpr std::array<const char*, 8> kFolderFileNames = {
    kRunReportName,        kTextReportName,       kJsonReportName,
    "jitter_report.html",  "perfetto_trace.json", "jitter_latency_histogram.png",
    "jitter_timeline.png", "jitter_causes.png"};

/// A folder for a new recording: created when missing, refused when it already holds files
/// (LTTng would mix two runs' streams, and the report would describe neither).
void PrepareOutputDir(const std::string& dir) {
  if (dir.empty()) ThrowUsage("--output DIR is required: the folder the trace and its report go to");
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) ThrowUsage("--output " + dir + ": exists and is not a folder");
    if (!fs::is_empty(dir, ec)) {
      ThrowUsage("--output " + dir +
            ": the folder already holds files; choose a new folder or remove its contents");
    }
    return;
  }
  if (!fs::create_directories(dir, ec)) {
    ThrowUsage("--output " + dir + ": cannot create the folder: " + ec.message());
  }
}

/// The recordings around the run, stopped in reverse order of their start.
struct Capture {
  std::optional<trace_capture::LttngSession> lttng;
  std::optional<trace_capture::KernelRecorder> kernel;
};

void StartCapture(const TraceOptions& o, Capture& capture) {
  try {
    if (o.kernel) {
      const std::string why = trace_capture::KernelRecorder::WhyCannotRecord();
      if (!why.empty()) throw trace_capture::CaptureError("--kernel: " + why);
    }
    trace_capture::LttngSessionConfig lttng;
    lttng.output_dir = o.output_dir;
    lttng.rate_hz = o.run.session.rate_hz;
    lttng.only_pid = static_cast<int>(::getpid());
    lttng.await_registration = true;  // a daemon started just now has not seen us yet
    capture.lttng.emplace(lttng);
    spdlog::info("recording LTTng session {} into {}", capture.lttng->session_name(), o.output_dir);
    if (o.kernel) {
      trace_capture::KernelRecorderConfig kernel;
      kernel.output_dir = o.output_dir;
      kernel.cpus = o.run.session.cpus;  // the loop's CPUs; none pinned: every CPU
      kernel.collector_cpus =
          kernel_glue::HelperCpus(kernel_glue::AllowedCpus(), o.run.session.cpus);
      capture.kernel.emplace(kernel);
      spdlog::info("recording the kernel's scheduler and interrupt events");
    }
  } catch (const trace_capture::CaptureError& e) {
    throw CommandError(ExitCode::kIo, e.what());
  }
}

/// The pictures need gnuplot; a missing or failing gnuplot costs the pictures, said aloud, not
/// the report.
std::vector<std::string> WritePictures(const analysis::JitterReport& report,
                                       const analysis::TimingTrace& trace, const std::string& dir) {
  try {
    return analysis::WriteJitterPlots(report, trace, dir);
  } catch (const analysis::InputError& e) {
    spdlog::warn("no PNG pictures: {}", e.what());
  } catch (const analysis::PlotError& e) {
    spdlog::warn("no PNG pictures: {}", e.what());
  }
  return {};
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.flush();
  if (!out) throw CommandError(ExitCode::kIo, "cannot write " + path);
}

/// Every output of the report into `dir`; prints the text report and the list of files.
void WriteOutputs(const analysis::JitterReport& report, const analysis::TimingTrace& trace,
                  const analysis::KernelTrace* kernel, const std::string& dir) {
  spdlog::info("writing the jitter report into {}", dir);
  const std::string text = analysis::FormatJitterText(report);
  std::vector<std::string> files = {dir + "/" + kTextReportName, dir + "/" + kJsonReportName};
  WriteText(files[0], text);
  WriteText(files[1], analysis::JitterToJson(report).dump(2) + "\n");
  for (std::string& png : WritePictures(report, trace, dir)) files.push_back(std::move(png));
  files.push_back(analysis::WriteJitterHtml(report, trace, dir));
  files.push_back(analysis::WritePerfettoTrace(report, trace, kernel, dir));
  std::fputs(text.c_str(), stdout);
  std::fprintf(stdout, "jitter report files:\n");
  for (const std::string& file : files) std::fprintf(stdout, "  %s\n", file.c_str());
  std::fflush(stdout);
}

/// After the report and its files: the warnings, and last of all an infeasible rate (also the
/// report's first line), so the console ends with the cause a user must act on first.
void PrintWarnings(const analysis::JitterReport& report) {
  for (const std::string& warning : report.warnings) spdlog::warn("{}", warning);
  if (!report.feasibility.feasible) spdlog::warn("{}", report.feasibility.verdict);
}

analysis::JitterReport Analyze(const analysis::TimingTrace& trace,
                               const analysis::KernelTrace* kernel) {
  spdlog::info("analysing {} cycles{}", trace.cycles.size(),
               kernel != nullptr
                   ? " with " + std::to_string(kernel->events.size()) + " kernel events"
                   : std::string());
  return analysis::AnalyzeJitter(trace, kernel);
}

std::string Us(std::int64_t ns) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f us", static_cast<double>(ns) * 1e-3);
  return text;
}

/// One bucket of the shared log-linear histogram: percentiles from the same values agree to
/// it (exact below 256 ns, then 1/128 of the value).
bool WithinResolution(std::int64_t a_ns, std::int64_t b_ns) {
  const std::int64_t larger = std::max(std::llabs(a_ns), std::llabs(b_ns));
  return std::llabs(a_ns - b_ns) <= std::max<std::int64_t>(1, larger / 128);
}

void CompareSummary(const char* name, const scheduler::TimingSummary& run,
                    const scheduler::TimingSummary& trace, std::vector<std::string>& out) {
  const std::pair<const char*, std::pair<std::int64_t, std::int64_t>> figures[] = {
      {"min", {run.min_ns, trace.min_ns}},
      {"p50", {run.p50_ns, trace.p50_ns}},
      {"p99", {run.p99_ns, trace.p99_ns}},
      {"p99.9", {run.p999_ns, trace.p999_ns}},
      {"max", {run.max_ns, trace.max_ns}}};
  for (const auto& [figure, values] : figures) {
    if (!WithinResolution(values.first, values.second)) {
      out.push_back(std::string(name) + " " + figure + ": run report " + Us(values.first) +
                    ", trace " + Us(values.second));
    }
  }
}

}  // namespace

std::vector<NamedFile> TraceOutputFiles(const std::string& dir) {
  std::vector<NamedFile> files;
  if (dir.empty()) return files;
  for (const char* name : kFolderFileNames) {
    files.push_back({"--output", (fs::path(dir) / name).string(), true});
  }
  return files;
}

std::vector<std::string> CompareWithRunReport(const runtime::RunReport& run,
                                              const analysis::JitterReport& trace) {
  std::vector<std::string> out;
  if (run.cycles_run != trace.cycles) {
    out.push_back("cycles: run report " + std::to_string(run.cycles_run) + ", trace " +
                  std::to_string(trace.cycles));
  }
  if (run.misses.deadline_misses != trace.misses) {
    out.push_back("deadline misses: run report " + std::to_string(run.misses.deadline_misses) +
                  ", trace " + std::to_string(trace.misses));
  }
  CompareSummary("latency", run.latency, trace.latency.summary, out);
  CompareSummary("compute", run.compute, trace.compute.summary, out);
  CompareSummary("response", run.response, trace.response.summary, out);
  CompareSummary("period jitter", run.period_jitter, trace.period_jitter.summary, out);
  return out;
}

int TraceTwin(const TraceOptions& o) {
  CheckTwinRunOptions(o.run);
  PrepareOutputDir(o.output_dir);
  Capture capture;
  StartCapture(o, capture);
  TwinRunOutcome outcome = RunTwin(o.run, "trace");
  std::optional<analysis::KernelTrace> kernel;
  try {
    if (capture.kernel) kernel = capture.kernel->Stop();
    const trace_capture::LttngChannelFigures figures = capture.lttng->Stop();
    spdlog::info("LTTng session stopped: {} events discarded", figures.discarded_events);
    WriteText(o.output_dir + "/" + kRunReportName,
              runtime::ToJson(outcome.report).dump(2) + "\n");
    const analysis::TimingTrace trace =
        analysis::ReadCtfTrace(o.output_dir, static_cast<int>(::getpid()));
    analysis::JitterReport report = Analyze(trace, kernel ? &*kernel : nullptr);
    for (const std::string& line : CompareWithRunReport(outcome.report, report)) {
      report.warnings.push_back("the trace disagrees with the run report: " + line);
    }
    WriteOutputs(report, trace, kernel ? &*kernel : nullptr, o.output_dir);
    PrintWarnings(report);
  } catch (const std::exception& e) {
    // The run happened and its report stands; the trace of it is what failed.
    std::fprintf(stderr, "hiltwin trace: the run ended, but its trace could not be made: %s\n",
                 e.what());
    return WorseExitCode(outcome.exit_code, static_cast<int>(ExitCode::kIo));
  }
  return outcome.exit_code;
}

int AnalyzeTrace(const TraceOptions& o) {
  const std::string& path = o.analyze_path;
  std::string dir = o.output_dir;
  std::error_code ec;
  const bool is_folder = fs::is_directory(path, ec);
  if (dir.empty()) dir = is_folder ? path : path + ".jitter";
  std::vector<NamedFile> files = TraceOutputFiles(dir);
  files.push_back({"--analyze", path, false});
  CheckFilesDistinct(files);
  try {
    spdlog::info("reading {}", path);
    const analysis::TimingTrace trace = analysis::ReadTrace(path, o.analyze_pid);
    std::optional<analysis::KernelTrace> kernel;
    if (is_folder && analysis::HasKernelTrace(path)) kernel = analysis::ReadKernelTrace(path);
    const analysis::JitterReport report = Analyze(trace, kernel ? &*kernel : nullptr);
    fs::create_directories(dir, ec);
    if (ec) ThrowUsage("--output " + dir + ": cannot create the folder: " + ec.message());
    WriteOutputs(report, trace, kernel ? &*kernel : nullptr, dir);
    PrintWarnings(report);
  } catch (const analysis::TraceReadError& e) {
    ThrowUsage(e.what());
  }
  return static_cast<int>(ExitCode::kPass);
}

}  // namespace hiltwin::app
