#pragma once
/// Everything `hiltwin trace` writes, derived from one JitterReport (and, for the per-cycle
/// pictures and the Perfetto export, the trace it came from).
///
///   DIR/jitter_report.txt     FormatJitterText
///   DIR/jitter_report.json    JitterToJson
///   DIR/jitter_latency_histogram.png, DIR/jitter_timeline.png, DIR/jitter_causes.png
///                              WriteJitterPlots (gnuplot, pngcairo)
///   DIR/jitter_report.html    WriteJitterHtml (self-contained: inline SVG, no script, no font)
///   DIR/perfetto_trace.json   WritePerfettoTrace (Chrome trace-event JSON: one slice per
///                              cycle, misses as instant events, with the kernel recorded the
///                              loop CPUs' other threads and interrupts; ui.perfetto.dev
///                              opens it)

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis {

[[nodiscard]] nlohmann::ordered_json JitterToJson(const JitterReport& report);

/// The text report: what a person reads first (a few screens at most).
[[nodiscard]] std::string FormatJitterText(const JitterReport& report);

/// Writes the PNG pictures with gnuplot; returns the paths written. Throws std::runtime_error
/// naming the file (or gnuplot's exit) when one cannot be made.
std::vector<std::string> WriteJitterPlots(const JitterReport& report, const TimingTrace& trace,
                                          const std::string& dir);

/// Writes the self-contained HTML page (the same three pictures as inline SVG, and the text
/// report); returns its path.
std::string WriteJitterHtml(const JitterReport& report, const TimingTrace& trace,
                            const std::string& dir);

/// Writes the Perfetto / Chrome trace-event JSON; returns its path. With `kernel` (the
/// recording the report was made from; null: none) each other thread that ran on the loop's
/// CPUs gets a track of the slices it ran, and each of those CPUs a track of its interrupts.
std::string WritePerfettoTrace(const JitterReport& report, const TimingTrace& trace,
                               const KernelTrace* kernel, const std::string& dir);

}  // namespace hiltwin::analysis
