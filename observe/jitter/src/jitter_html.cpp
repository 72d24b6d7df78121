#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_format.h"
#include "hiltwin/report_kit/svg_chart.h"
#include "hiltwin/report_kit/time_units.h"

namespace hiltwin::analysis {
namespace {

using detail::Us;

using detail::SvgAxis;
using detail::SvgChart;

constexpr int kWidthPx = 900;
constexpr int kHeightPx = 340;
constexpr std::size_t kMaxSvgPoints = 3000;
constexpr std::size_t kMaxSvgBins = 120;
constexpr const char* kBlue = "#1f77b4";
constexpr const char* kGreen = "#2ca02c";
constexpr const char* kOrange = "#ff7f0e";
constexpr const char* kRed = "#d62728";


std::string HistogramSvg(const JitterReport& r) {
  const std::vector<HistogramBin> bins = detail::LogDisplayBins(r.latency, kMaxSvgBins);
  std::uint64_t most = 1;
  for (const HistogramBin& b : bins) most = std::max(most, b.count);
  const double x_min = bins.empty() ? 1.0 : Us(std::max<std::int64_t>(bins.front().low_ns, 1));
  const double x_max = bins.empty() ? 10.0 : Us(bins.back().high_ns);
  SvgChart chart(kWidthPx, kHeightPx,
                 {x_min / 1.5, std::max(x_max * 1.5, x_min * 10.0), true, "wake-up latency [us]"},
                 {0.5, static_cast<double>(most) * 2.0, true, "cycles (log scale)"},
                 "wake-up latency histogram, " + std::to_string(r.latency.summary.count) + " cycles");
  chart.Axes();
  for (const HistogramBin& b : bins) {
    chart.Bar(Us(std::max<std::int64_t>(b.low_ns, 1)), Us(b.high_ns), 0.5,
              static_cast<double>(b.count), kBlue);
  }
  const scheduler::TimingSummary& s = r.latency.summary;
  chart.VerticalMarker(Us(s.p50_ns), "", kGreen);
  chart.VerticalMarker(Us(s.p99_ns), "", kOrange);
  chart.VerticalMarker(Us(s.p999_ns), "", kRed);
  chart.Legend("cycles per bin", kBlue);
  chart.Legend("p50 " + detail::FormatDuration(s.p50_ns), kGreen, true);
  chart.Legend("p99 " + detail::FormatDuration(s.p99_ns), kOrange, true);
  chart.Legend("p99.9 " + detail::FormatDuration(s.p999_ns), kRed, true);
  return chart.Finish();
}

std::string TimelineSvg(const JitterReport& r, const TimingTrace& trace) {
  const std::vector<detail::PlotPoint> points = detail::ThinnedCycles(trace, kMaxSvgPoints);
  std::vector<double> t, latency, compute, miss_t, miss_latency;
  double lo = Us(r.deadline_ns);
  double hi = lo;
  for (const detail::PlotPoint& p : points) {
    t.push_back(p.t_s);
    latency.push_back(p.latency_us);
    compute.push_back(p.compute_us);
    for (const double v : {p.latency_us, p.compute_us}) {
      if (v > 0.0) lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (p.missed) {
      miss_t.push_back(p.t_s);
      miss_latency.push_back(p.compute_us);
    }
  }
  const double t_max = t.empty() ? 1.0 : std::max(t.back(), 1e-6);
  SvgChart chart(kWidthPx, kHeightPx, {0.0, t_max, false, "time since the first release [s]"},
                 {std::max(lo / 1.5, 1e-3), hi * 1.5, true, "[us] (log scale)"},
                 "latency and compute of every cycle; misses in red");
  chart.Axes();
  chart.Line(t, latency, kBlue);
  chart.Line(t, compute, kGreen);
  chart.Dots(miss_t, miss_latency, kRed);
  chart.HorizontalMarker(Us(r.deadline_ns), "deadline " + detail::FormatDuration(r.deadline_ns), "#7f7f7f");
  chart.Legend("wake-up latency", kBlue);
  chart.Legend("compute", kGreen);
  chart.Legend("deadline miss (at its compute)", kRed);
  return chart.Finish();
}

std::string CausesSvg(const JitterReport& r) {
  const std::vector<detail::CauseBar> bars = detail::CauseBars(r);
  std::uint64_t most = 1;
  for (const detail::CauseBar& b : bars) most = std::max(most, b.cycles);
  const auto n = static_cast<double>(std::max<std::size_t>(bars.size(), 1));
  SvgChart chart(kWidthPx, kHeightPx, {0.0, n, false, "dominant cause", false},
                 {0.0, static_cast<double>(most) * 1.25, false, "notable cycles", true, true},
                 "causes of the late cycles");
  if (!r.kernel_recorded || bars.empty()) {
    chart.Note(!r.kernel_recorded ? detail::kCausesNotRecorded
                                  : "no notable cycle: no miss and no wake-up above p99.9");
    return chart.Finish();
  }
  chart.Axes();
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const double x = static_cast<double>(i);
    chart.Bar(x + 0.1, x + 0.5, 0.0, static_cast<double>(bars[i].cycles), kBlue);
    chart.Bar(x + 0.5, x + 0.9, 0.0, static_cast<double>(bars[i].misses), kRed);
    chart.Label(x + 0.3, static_cast<double>(bars[i].cycles), std::to_string(bars[i].cycles),
                "middle");
    chart.Label(x + 0.7, static_cast<double>(bars[i].misses), std::to_string(bars[i].misses),
                "middle");
    chart.XCategory(x + 0.5, bars[i].label);
  }
  chart.Legend("notable cycles", kBlue);
  chart.Legend("of them misses", kRed);
  return chart.Finish();
}

}  // namespace

namespace {

// The summary cards, on top of the page style every analysis page shares.
constexpr const char* kCardStyle =
    ".cards{display:flex;flex-wrap:wrap;gap:10px;margin:14px 0}"
    ".card{border:1px solid #ddd;border-radius:6px;padding:8px 12px;min-width:120px}"
    ".card b{display:block;font-size:20px}.card span{color:#666;font-size:12px}"
    ".bad b{color:#d62728}";

std::string Card(const std::string& value, const std::string& what, bool bad) {
  return std::string("<div class=\"card") + (bad ? " bad" : "") + "\"><b>" +
         detail::HtmlEscape(value) + "</b><span>" + detail::HtmlEscape(what) + "</span></div>";
}

std::string Cards(const JitterReport& r) {
  char pct[32];
  std::snprintf(pct, sizeof pct, "%.3f %%", r.miss_pct);
  std::string top_cause = r.kernel_recorded ? "none" : "not recorded";
  if (!r.causes.empty()) top_cause = ToString(r.causes.front().cause);
  std::string out = "<div class=\"cards\">";
  out += Card(std::to_string(r.cycles), "cycles", false);
  out += Card(std::to_string(r.misses), "deadline misses", r.misses > 0);
  out += Card(pct, "of judged releases missed", r.misses > 0);
  out += Card(detail::FormatDuration(r.latency.summary.p999_ns), "wake-up latency p99.9", false);
  out += Card(detail::FormatDuration(r.latency.summary.max_ns), "worst wake-up latency", false);
  out += Card(detail::FormatDuration(r.response.summary.max_ns), "worst response", false);
  out += Card(top_cause, "most frequent cause", false);
  out += Card(std::to_string(r.discarded_events), "events discarded", r.discarded_events > 0);
  return out + "</div>\n";
}

}  // namespace

std::string WriteJitterHtml(const JitterReport& report, const TimingTrace& trace,
                            const std::string& dir) {
  std::string path = (std::filesystem::path(dir) / "jitter_report.html").string();
  std::ofstream out(path);
  if (!out) {
    throw std::runtime_error("cannot write " + path + ": check that the directory exists and is writable");
  }
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<title>hiltwin jitter report</title>\n<style>" << detail::kPageStyle << kCardStyle
      << "</style>\n</head>\n<body>\n"
      << "<h1>hiltwin jitter report</h1>\n<p class=\"sub\">" << detail::HtmlEscape(report.path)
      << " (" << detail::SourceName(report.source) << "), period "
      << detail::FormatDuration(report.period_ns) << ", deadline "
      << detail::FormatDuration(report.deadline_ns) << "</p>\n"
      << Cards(report) << "<h2>Wake-up latency</h2>\n" << HistogramSvg(report)
      << "<h2>Every cycle over time</h2>\n" << TimelineSvg(report, trace)
      << "<h2>Why cycles were late</h2>\n" << CausesSvg(report)
      << "<h2>Report</h2>\n<pre>" << detail::HtmlEscape(FormatJitterText(report)) << "</pre>\n"
      << "</body>\n</html>\n";
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path + ": the disk may be full");
  return path;
}

}  // namespace hiltwin::analysis
