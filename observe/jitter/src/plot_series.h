#pragma once
// Private to the analysis module: what the pictures (gnuplot PNGs and the HTML page's SVGs)
// draw beyond the thinned per-cycle series of jitter_format.h — the misses (as markers while
// they are few, as a density strip always), axis ranges that hold the deadline, and the named
// culprits of the causes chart — so both renderings show the same figures.

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/traces/timing_trace.h"
#include "jitter_format.h"

namespace hiltwin::analysis::detail {

/// The colours of both renderings.
inline constexpr const char* kBlue = "#1f77b4";
inline constexpr const char* kGreen = "#2ca02c";
inline constexpr const char* kOrange = "#ff7f0e";
inline constexpr const char* kRed = "#d62728";
inline constexpr const char* kPurple = "#9467bd";
inline constexpr const char* kDeadline = "#000000";

/// At most this many misses are drawn as markers: at 20 kHz an infeasible rate misses tens of
/// thousands of cycles, whose markers would cover the panels; the strip shows them instead.
inline constexpr std::size_t kMaxMissMarkers = 100;

/// Every missed cycle when there are at most kMaxMissMarkers, else none.
[[nodiscard]] std::vector<PlotPoint> MissMarkers(const TimingTrace& trace);

/// Seconds from the first release to the last: the time axis.
[[nodiscard]] double TraceSpanS(const TimingTrace& trace);

/// One bin of the miss strip: [from_s, to_s) since the first release, the cycles released in
/// it and how many of them missed.
struct StripBin {
  double from_s = 0.0;
  double to_s = 0.0;
  std::uint64_t cycles = 0;
  std::uint64_t missed = 0;
};
/// The trace's span in `bins` equal bins (the last one closed): where the misses fell.
[[nodiscard]] std::vector<StripBin> MissStrip(const TimingTrace& trace, std::size_t bins);

/// The range of a log axis holding every positive value added, with a margin of 1.5 each side.
class LogRange {
 public:
  void Add(double v) noexcept;
  [[nodiscard]] double Low() const noexcept;
  [[nodiscard]] double High() const noexcept;

 private:
  double lo_ = std::numeric_limits<double>::infinity();
  double hi_ = 0.0;
};

/// One bar of the causes chart: a culprit ("rt-hog (pid 4242)", "local_timer"), its cause
/// class, the notable cycles it is dominant in and the misses among them.
struct CauseBar {
  std::string label;
  std::string cause;  ///< the class ("" for the bar of the other culprits)
  std::uint64_t cycles = 0;
  std::uint64_t misses = 0;
};
/// A culprit's name as two lines: "rt-hog" and "(pid 4242)"; ("local_timer", "") unsplit.
[[nodiscard]] std::pair<std::string, std::string> SplitCulprit(const std::string& name);

/// The `top` culprits of the most notable cycles (most first; ties: the earlier first), and one
/// bar "N other culprits" for the rest. Empty without the kernel.
[[nodiscard]] std::vector<CauseBar> CauseBars(const JitterReport& report, std::size_t top = 5);

}  // namespace hiltwin::analysis::detail
