#pragma once
// Private to the analysis module: the small pieces every jitter output shares (durations as a
// person reads them, names of enums defined elsewhere, the per-cycle series the pictures draw),
// so the text, the HTML, the PNGs and the evidence lines say a figure the same way.

#include <cstdint>
#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis::detail {

/// "850 ns", "4.2 us", "35 us", "2.10 ms", "1.250 s".
[[nodiscard]] std::string FormatDuration(std::int64_t ns);

/// "lttng" / "timing_log". A local switch: ToString(TraceSource) belongs to the readers, and
/// the jitter report must not depend on which of them is linked.
[[nodiscard]] const char* SourceName(TraceSource source) noexcept;

/// "SCHED_OTHER", "SCHED_FIFO", "SCHED_RR" for the loop thread's policy number.
[[nodiscard]] const char* PolicyName(int policy) noexcept;

/// One cycle as the pictures draw it: time since the first release, in seconds, and µs.
struct PlotPoint {
  double t_s = 0.0;
  double latency_us = 0.0;
  double compute_us = 0.0;
  double response_us = 0.0;  ///< release to end: what the deadline bounds
  bool missed = false;
};
/// `s` as a point, its time counted from the release `t0_ns`.
[[nodiscard]] PlotPoint PointOf(const scheduler::TimingSample& s, std::int64_t t0_ns);

/// The cycles to draw: all of them when there are at most `max_points`, else per bucket of
/// consecutive cycles the ones with the smallest and largest latency, the largest compute, the
/// largest response and the first miss, in time order, so spikes and misses survive thinning.
[[nodiscard]] std::vector<PlotPoint> ThinnedCycles(const TimingTrace& trace,
                                                   std::size_t max_points);

/// A histogram merged into at most `max_bins` bins of equal width on a log scale (bins of the
/// exact range below 1 µs stay apart only as far as the scale allows), for drawing.
[[nodiscard]] std::vector<HistogramBin> LogDisplayBins(const Distribution& distribution,
                                                       std::size_t max_bins);

/// The line every output shows when the kernel was not recorded.
inline constexpr const char* kCausesNotRecorded =
    "causes were not recorded: run `hiltwin trace --kernel`";

}  // namespace hiltwin::analysis::detail
