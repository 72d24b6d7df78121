#include "jitter_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace hiltwin::analysis::detail {

std::string FormatDuration(std::int64_t ns) {
  char text[48];
  const double value = static_cast<double>(ns);
  const std::int64_t magnitude = ns < 0 ? -ns : ns;
  if (magnitude < 1000) {
    std::snprintf(text, sizeof text, "%lld ns", static_cast<long long>(ns));
  } else if (magnitude < 10'000) {
    std::snprintf(text, sizeof text, "%.1f us", value / 1e3);
  } else if (magnitude < 1'000'000) {
    std::snprintf(text, sizeof text, "%.0f us", value / 1e3);
  } else if (magnitude < 1'000'000'000) {
    std::snprintf(text, sizeof text, "%.2f ms", value / 1e6);
  } else {
    std::snprintf(text, sizeof text, "%.3f s", value / 1e9);
  }
  return text;
}

const char* SourceName(TraceSource source) noexcept {
  switch (source) {
    case TraceSource::kLttng: return "lttng";
    case TraceSource::kTimingLog: return "timing_log";
  }
  return "unknown";
}

const char* PolicyName(int policy) noexcept {
  switch (policy) {
    case 0: return "SCHED_OTHER";
    case 1: return "SCHED_FIFO";
    case 2: return "SCHED_RR";
    case 3: return "SCHED_BATCH";
    case 5: return "SCHED_IDLE";
    case 6: return "SCHED_DEADLINE";
    default: return "unknown";
  }
}

PlotPoint PointOf(const scheduler::TimingSample& s, std::int64_t t0_ns) {
  PlotPoint p;
  p.t_s = static_cast<double>(s.release_ns - t0_ns) * 1e-9;
  p.latency_us = static_cast<double>(s.wake_ns - s.release_ns) * 1e-3;
  p.compute_us = static_cast<double>(s.end_ns - s.start_ns - s.io_ns) * 1e-3;
  p.response_us = static_cast<double>(s.end_ns - s.release_ns) * 1e-3;
  p.missed = s.missed;
  return p;
}

namespace {

// The rows of [begin, end) worth keeping, in time order.
void KeepExtremes(const std::vector<TracedCycle>& cycles, std::size_t begin, std::size_t end,
                  std::vector<std::size_t>& rows) {
  auto latency = [&](std::size_t i) { return cycles[i].sample.wake_ns - cycles[i].sample.release_ns; };
  auto compute = [&](std::size_t i) {
    const auto& s = cycles[i].sample;
    return s.end_ns - s.start_ns - s.io_ns;
  };
  auto response = [&](std::size_t i) {
    return cycles[i].sample.end_ns - cycles[i].sample.release_ns;
  };
  std::size_t lo = begin;
  std::size_t hi = begin;
  std::size_t heavy = begin;
  std::size_t slow = begin;
  std::size_t miss = end;
  for (std::size_t i = begin; i < end; ++i) {
    if (latency(i) < latency(lo)) lo = i;
    if (latency(i) > latency(hi)) hi = i;
    if (compute(i) > compute(heavy)) heavy = i;
    if (response(i) > response(slow)) slow = i;
    if (miss == end && cycles[i].sample.missed) miss = i;
  }
  std::size_t picked[5] = {lo, hi, heavy, slow, miss};
  std::sort(std::begin(picked), std::end(picked));
  for (std::size_t i = 0; i < 5; ++i) {
    if (picked[i] == end || (i > 0 && picked[i] == picked[i - 1])) continue;
    rows.push_back(picked[i]);
  }
}

}  // namespace

std::vector<PlotPoint> ThinnedCycles(const TimingTrace& trace, std::size_t max_points) {
  std::vector<PlotPoint> points;
  const std::size_t n = trace.cycles.size();
  if (n == 0) return points;
  const std::int64_t t0_ns = trace.cycles.front().sample.release_ns;
  if (n <= max_points || max_points < 8) {
    points.reserve(n);
    for (const TracedCycle& c : trace.cycles) points.push_back(PointOf(c.sample, t0_ns));
    return points;
  }
  const std::size_t buckets = max_points / 5;
  std::vector<std::size_t> rows;
  rows.reserve(max_points);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = b * n / buckets;
    const std::size_t end = (b + 1) * n / buckets;
    if (begin < end) KeepExtremes(trace.cycles, begin, end, rows);
  }
  points.reserve(rows.size());
  for (const std::size_t i : rows) points.push_back(PointOf(trace.cycles[i].sample, t0_ns));
  return points;
}

std::vector<HistogramBin> LogDisplayBins(const Distribution& distribution, std::size_t max_bins) {
  const std::vector<HistogramBin>& bins = distribution.bins;
  if (bins.size() <= max_bins || max_bins == 0) return bins;
  const double lo = std::log(static_cast<double>(std::max<std::int64_t>(bins.front().low_ns, 1)));
  const double hi = std::log(static_cast<double>(std::max<std::int64_t>(bins.back().high_ns, 2)));
  const double span = std::max(hi - lo, 1e-9);
  std::vector<HistogramBin> out;
  std::size_t current = max_bins;  // display bin of out.back()
  for (const HistogramBin& bin : bins) {
    const double x = std::log(static_cast<double>(std::max<std::int64_t>(bin.low_ns, 1)));
    const auto slot = std::min(
        max_bins - 1, static_cast<std::size_t>(std::max(0.0, (x - lo) / span) *
                                               static_cast<double>(max_bins)));
    if (out.empty() || slot != current) {
      out.push_back(bin);
      current = slot;
    } else {
      out.back().high_ns = bin.high_ns;
      out.back().count += bin.count;
    }
  }
  return out;
}

}  // namespace hiltwin::analysis::detail
