#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_format.h"
#include "plot_series.h"
#include "hiltwin/report_kit/svg_chart.h"
#include "hiltwin/report_kit/time_units.h"

namespace hiltwin::analysis {
namespace {

using detail::Us;

using detail::SvgAxis;
using detail::SvgChart;

constexpr int kWidthPx = 900;
constexpr int kHeightPx = 340;
constexpr int kTimelineHeightPx = 380;  // the miss strip on top of the plot
constexpr double kStripPx = 28.0;
constexpr std::size_t kSvgStripBins = 200;  // about 4 px each
constexpr std::size_t kMaxSvgPoints = 3000;
constexpr std::size_t kMaxSvgBins = 120;
constexpr std::size_t kCulpritChars = 24;  // fits a sixth of the chart's width
using detail::kBlue;
using detail::kGreen;
using detail::kDeadline;
using detail::kOrange;
using detail::kPurple;
using detail::kRed;

std::string HistogramSvg(const JitterReport& r) {
  const std::vector<HistogramBin> bins = detail::LogDisplayBins(r.latency, kMaxSvgBins);
  std::uint64_t most = 1;
  detail::LogRange x;
  x.Add(Us(r.deadline_ns));
  for (const HistogramBin& b : bins) {
    most = std::max(most, b.count);
    x.Add(Us(std::max<std::int64_t>(b.low_ns, 1)));
    x.Add(Us(b.high_ns));
  }
  SvgChart chart(kWidthPx, kHeightPx, {x.Low(), x.High(), true, "wake-up latency [us]"},
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
  chart.VerticalMarker(Us(r.deadline_ns), "", kDeadline);
  chart.Legend("cycles per bin", kBlue);
  chart.Legend("p50 " + detail::FormatDuration(s.p50_ns), kGreen, true);
  chart.Legend("p99 " + detail::FormatDuration(s.p99_ns), kOrange, true);
  chart.Legend("p99.9 " + detail::FormatDuration(s.p999_ns), kRed, true);
  chart.Legend("deadline " + detail::FormatDuration(r.deadline_ns), kDeadline, true);
  return chart.Finish();
}

// The share of cycles missed per time bin, as the strip's bars.
std::vector<detail::StripBar> MissStripBars(const TimingTrace& trace) {
  std::vector<detail::StripBar> bars;
  for (const detail::StripBin& b : detail::MissStrip(trace, kSvgStripBins)) {
    if (b.cycles == 0) continue;
    const double share = static_cast<double>(b.missed) / static_cast<double>(b.cycles);
    bars.push_back({b.from_s, b.to_s, share});
  }
  return bars;
}

// Latency and response of every cycle (thinned) against the deadline; the misses as dots at
// their response while they are few, and always as a strip of the share missed over time.
std::string TimelineSvg(const JitterReport& r, const TimingTrace& trace) {
  std::vector<double> t, latency, compute, response, miss_t, miss_response;
  detail::LogRange y;
  y.Add(Us(r.deadline_ns));
  for (const detail::PlotPoint& p : detail::ThinnedCycles(trace, kMaxSvgPoints)) {
    t.push_back(p.t_s);
    latency.push_back(p.latency_us);
    compute.push_back(p.compute_us);
    response.push_back(p.response_us);
    for (const double v : {p.latency_us, p.compute_us, p.response_us}) y.Add(v);
  }
  for (const detail::PlotPoint& p : detail::MissMarkers(trace)) {
    miss_t.push_back(p.t_s);
    miss_response.push_back(p.response_us);
  }
  SvgChart chart(kWidthPx, kTimelineHeightPx,
                 {0.0, std::max(detail::TraceSpanS(trace), 1e-6), false,
                  "time since the first release [s]"},
                 {y.Low(), y.High(), true, "[us] (log scale)"},
                 "every cycle against the deadline; above: share of cycles missed", kStripPx);
  chart.Axes();
  chart.Strip(MissStripBars(trace), "missed", kRed);
  chart.Line(t, compute, kGreen);
  chart.Line(t, response, kPurple);
  chart.Line(t, latency, kBlue);  // over the response, which it is a part of
  chart.Dots(miss_t, miss_response, kRed);
  chart.HorizontalMarker(Us(r.deadline_ns), "deadline " + detail::FormatDuration(r.deadline_ns),
                         kDeadline);
  chart.Legend("wake-up latency", kBlue);
  chart.Legend("compute", kGreen);
  chart.Legend("response (release to end)", kPurple);
  const bool too_many = miss_t.empty() && r.misses > 0;
  chart.Legend(too_many ? "misses: too many to mark, see the strip"
                        : "deadline miss (at its response)",
               kRed);
  return chart.Finish();
}

// A culprit's name cut to fit its bar's width.
std::string Fit(const std::string& name) {
  return name.size() <= kCulpritChars ? name : name.substr(0, kCulpritChars - 3) + "...";
}

std::string CausesSvg(const JitterReport& r) {
  const std::vector<detail::CauseBar> bars = detail::CauseBars(r);
  std::uint64_t most = 1;
  for (const detail::CauseBar& b : bars) most = std::max(most, b.cycles);
  const auto n = static_cast<double>(std::max<std::size_t>(bars.size(), 1));
  SvgChart chart(kWidthPx, kHeightPx, {0.0, n, false, "", false},
                 {0.0, static_cast<double>(most) * 1.25, false, "notable cycles", true, true},
                 "causes of the late cycles: the culprits of the most, and their class");
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
    const auto [name, pid] = detail::SplitCulprit(bars[i].label);
    chart.XCategory(x + 0.5, Fit(name));
    if (!pid.empty()) chart.XCategory(x + 0.5, pid, 1);
    chart.XCategory(x + 0.5, bars[i].cause, pid.empty() ? 1 : 2);
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
