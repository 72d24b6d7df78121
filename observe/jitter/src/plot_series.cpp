#include "plot_series.h"

#include <algorithm>
#include <map>
#include <utility>

#include "cause_attribution.h"

namespace hiltwin::analysis::detail {

namespace {

double SecondsSince(std::int64_t t0_ns, std::int64_t t_ns) {
  return static_cast<double>(t_ns - t0_ns) * 1e-9;
}

}  // namespace

std::vector<PlotPoint> MissMarkers(const TimingTrace& trace) {
  std::vector<PlotPoint> out;
  if (trace.cycles.empty()) return out;
  const std::int64_t t0_ns = trace.cycles.front().sample.release_ns;
  for (const TracedCycle& c : trace.cycles) {
    if (!c.sample.missed) continue;
    if (out.size() == kMaxMissMarkers) return {};
    out.push_back(PointOf(c.sample, t0_ns));
  }
  return out;
}

double TraceSpanS(const TimingTrace& trace) {
  if (trace.cycles.empty()) return 0.0;
  return SecondsSince(trace.cycles.front().sample.release_ns,
                      trace.cycles.back().sample.release_ns);
}

std::vector<StripBin> MissStrip(const TimingTrace& trace, std::size_t bins) {
  if (trace.cycles.empty() || bins == 0) return {};
  const double span = std::max(TraceSpanS(trace), 1e-9);
  std::vector<StripBin> out(bins);
  for (std::size_t i = 0; i < bins; ++i) {
    out[i].from_s = span * static_cast<double>(i) / static_cast<double>(bins);
    out[i].to_s = span * static_cast<double>(i + 1) / static_cast<double>(bins);
  }
  const std::int64_t t0_ns = trace.cycles.front().sample.release_ns;
  for (const TracedCycle& c : trace.cycles) {
    const double t = SecondsSince(t0_ns, c.sample.release_ns);
    auto i = static_cast<std::size_t>(t / span * static_cast<double>(bins));
    i = std::min(i, bins - 1);
    if (i + 1 < bins && t >= out[i].to_s) ++i;  // the bin's own edges decide, not the rounding
    if (t < out[i].from_s && i > 0) --i;
    ++out[i].cycles;
    if (c.sample.missed) ++out[i].missed;
  }
  return out;
}

void LogRange::Add(double v) noexcept {
  if (!(v > 0.0)) return;
  lo_ = std::min(lo_, v);
  hi_ = std::max(hi_, v);
}

double LogRange::Low() const noexcept { return hi_ > 0.0 ? lo_ / 1.5 : 1.0; }

double LogRange::High() const noexcept {
  return hi_ > 0.0 ? std::max(hi_ * 1.5, Low() * 10.0) : 10.0;
}

std::pair<std::string, std::string> SplitCulprit(const std::string& name) {
  const std::size_t at = name.find(" (");
  if (at == std::string::npos) return {name, ""};
  return {name.substr(0, at), name.substr(at + 1)};
}

std::vector<CauseBar> CauseBars(const JitterReport& report, std::size_t top) {
  if (!report.kernel_recorded) return {};
  // Per (class, culprit), in order of the first notable cycle it explains.
  std::map<std::pair<CauseClass, std::string>, std::size_t> index;
  std::vector<CauseBar> bars;
  for (const NotableCycle& n : report.notable) {
    std::string name = CulpritName(n.cause);
    if (name.empty()) name = ToString(n.cause.cause);
    const auto [it, fresh] = index.try_emplace({n.cause.cause, name}, bars.size());
    if (fresh) bars.push_back({name, ToString(n.cause.cause), 0, 0});
    ++bars[it->second].cycles;
    if (n.missed) ++bars[it->second].misses;
  }
  std::stable_sort(bars.begin(), bars.end(), [](const CauseBar& a, const CauseBar& b) {
    return a.cycles != b.cycles ? a.cycles > b.cycles : a.misses > b.misses;
  });
  if (bars.size() <= top) return bars;
  CauseBar others{std::to_string(bars.size() - top) + " other culprit" +
                      (bars.size() - top == 1 ? "" : "s"),
                  "", 0, 0};
  for (std::size_t i = top; i < bars.size(); ++i) {
    others.cycles += bars[i].cycles;
    others.misses += bars[i].misses;
  }
  bars.resize(top);
  bars.push_back(std::move(others));
  return bars;
}

}  // namespace hiltwin::analysis::detail
