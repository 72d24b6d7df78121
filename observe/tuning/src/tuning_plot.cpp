#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hiltwin/report_kit/svg_chart.h"
#include "hiltwin/tuning/tuning_report.h"
#include "tuning_format.h"

namespace hiltwin::analysis {
namespace {

using detail::HtmlEscape;
using detail::HzText;
using detail::SvgAxis;
using detail::SvgChart;

constexpr int kWidthPx = 900;
constexpr int kHeightPx = 360;
// A log axis has no zero: runs without a miss are drawn here and labelled "0".
constexpr double kMissFloorPct = 1e-3;
constexpr const char* kBlue = "#1f77b4";
constexpr const char* kGreen = "#2ca02c";
constexpr const char* kOrange = "#ff7f0e";
constexpr const char* kRed = "#d62728";
constexpr const char* kPurple = "#9467bd";
constexpr const char* kGrey = "#7f7f7f";
constexpr const char* kBrown = "#8c564b";

// The two timing bounds are charted only up to the scheduler's limit: a fast model's method-2
// maximum can be megahertz and would squash every run into the left edge.
bool OnChart(double rate_hz, const TuneReport& r) {
  return rate_hz > 0.0 && rate_hz <= r.policy.max_rate_hz;
}

// The rate axis spans the candidates and every marked bound.
SvgAxis RateAxis(const TuneReport& r) {
  const Recommendation& rec = r.recommendation;
  std::vector<double> rates_hz = {rec.recommended_hz};
  for (const double bound_hz : {rec.timing_max_hz, rec.latency_max_hz}) {
    if (OnChart(bound_hz, r)) rates_hz.push_back(bound_hz);
  }
  if (rec.accuracy_bound_hz) rates_hz.push_back(*rec.accuracy_bound_hz);
  for (const CandidateResult& c : r.candidates) rates_hz.push_back(c.rate_hz);
  for (const AccuracyPoint& p : r.accuracy.points) rates_hz.push_back(p.rate_hz);
  std::erase_if(rates_hz, [](double v) { return !(v > 0.0); });
  const auto [lo, hi] = std::minmax_element(rates_hz.begin(), rates_hz.end());
  const double lo_hz = rates_hz.empty() ? 100.0 : *lo;
  const double hi_hz = rates_hz.empty() ? 1e4 : *hi;
  return {lo_hz / 1.5, std::max(hi_hz * 1.5, lo_hz * 10.0), true, "twin update rate [Hz]"};
}

// A bound's dashed marker with its legend entry; beyond the chart only the legend, saying so.
void BoundMarker(SvgChart& chart, const TuneReport& r, double rate_hz, const std::string& name,
                 const char* colour) {
  if (OnChart(rate_hz, r)) {
    chart.VerticalMarker(rate_hz, "", colour);
    chart.Legend(name + " " + HzText(rate_hz), colour, true);
  } else {
    chart.Legend(name + " " + HzText(rate_hz) + " (off the chart: above " +
                     HzText(r.policy.max_rate_hz) + ")",
                 colour, true);
  }
}

// The rates both charts mark, with one legend entry each.
void RateMarkers(SvgChart& chart, const TuneReport& r) {
  const Recommendation& rec = r.recommendation;
  BoundMarker(chart, r, rec.timing_max_hz, "timing maximum", kGrey);
  BoundMarker(chart, r, rec.latency_max_hz, "latency-aware maximum", kBrown);
  if (rec.accuracy_bound_hz) {
    chart.VerticalMarker(*rec.accuracy_bound_hz, "", kPurple);
    chart.Legend("accuracy bound " + HzText(*rec.accuracy_bound_hz), kPurple, true);
  }
  chart.VerticalMarker(rec.recommended_hz, "", kGreen);
  chart.Legend("recommended " + HzText(rec.recommended_hz), kGreen, true);
}

std::string MissSvg(const TuneReport& r) {
  std::vector<double> rates_hz, miss_pct;
  double most_pct = 1.0;
  for (const CandidateResult& c : r.candidates) {
    rates_hz.push_back(c.rate_hz);
    miss_pct.push_back(std::max(c.miss_pct, kMissFloorPct));
    most_pct = std::max(most_pct, c.miss_pct);
  }
  SvgChart chart(kWidthPx, kHeightPx, RateAxis(r),
                 {kMissFloorPct / 2.0, most_pct * 3.0, true, "deadline misses [%] (log scale)"},
                 "deadline misses against rate (no miss: drawn at the floor, labelled 0)");
  chart.Axes();
  chart.Line(rates_hz, miss_pct, kBlue);
  chart.Dots(rates_hz, miss_pct, kBlue);
  for (const CandidateResult& c : r.candidates) {
    if (c.miss_pct <= 0.0) chart.Label(c.rate_hz, kMissFloorPct, "0", "middle");
  }
  if (r.candidates.empty()) chart.Note("no validation runs");
  chart.Legend("validation runs", kBlue);
  RateMarkers(chart, r);
  return chart.Finish();
}

std::string ErrorSvg(const TuneReport& r) {
  std::vector<double> rates_hz, error_mm, search_hz, search_mm;
  const double tolerance_mm = r.policy.tolerance_m * 1e3;
  double lo_mm = tolerance_mm;
  double hi_mm = tolerance_mm;
  auto add = [&](double rate_hz, double rms_m, std::vector<double>& xs, std::vector<double>& ys) {
    xs.push_back(rate_hz);
    ys.push_back(rms_m * 1e3);
    if (rms_m > 0.0) lo_mm = std::min(lo_mm, rms_m * 1e3);
    hi_mm = std::max(hi_mm, rms_m * 1e3);
  };
  for (const CandidateResult& c : r.candidates) add(c.rate_hz, c.rms_error_m, rates_hz, error_mm);
  for (const AccuracyPoint& p : r.accuracy.points)
    add(p.rate_hz, p.rms_error_m, search_hz, search_mm);
  SvgChart chart(kWidthPx, kHeightPx, RateAxis(r),
                 {lo_mm / 2.0, hi_mm * 2.0, true, "RMS wheel-position error [mm] (log scale)"},
                 "RMS error as the controller sees it, against rate");
  chart.Axes();
  chart.Line(rates_hz, error_mm, kBlue);
  chart.Dots(rates_hz, error_mm, kBlue);
  chart.Dots(search_hz, search_mm, kOrange);
  chart.HorizontalMarker(tolerance_mm, "tolerance " + detail::MmText(r.policy.tolerance_m), kRed);
  if (r.candidates.empty() && r.accuracy.points.empty()) chart.Note("no error was measured");
  chart.Legend("validation runs", kBlue);
  chart.Legend("accuracy search", kOrange);
  RateMarkers(chart, r);
  return chart.Finish();
}

}  // namespace

void WriteTunePlotHtml(const TuneReport& report, const std::string& html_path) {
  std::ofstream out(html_path);
  if (!out) {
    throw std::runtime_error("cannot write " + html_path +
                             ": check that the directory exists and is writable");
  }
  const Recommendation& rec = report.recommendation;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<title>hiltwin tune</title>\n<style>" << detail::kPageStyle
      << "</style>\n</head>\n<body>\n"
      << "<h1>hiltwin tune: recommended " << HzText(rec.recommended_hz) << "</h1>\n"
      << "<p class=\"sub\">" << HtmlEscape(report.model) << ", " << HtmlEscape(report.clock)
      << " clock; decided by: " << HtmlEscape(rec.reason) << "</p>\n"
      << "<p>Dashed lines: grey the timing maximum 1/(overhead + compute), brown the "
         "latency-aware maximum, purple the accuracy bound, green the recommended rate; red the "
         "RMS error tolerance.</p>\n"
      << "<h2>Deadline misses</h2>\n"
      << MissSvg(report) << "<h2>Accuracy</h2>\n"
      << ErrorSvg(report) << "<h2>Report</h2>\n<pre>" << HtmlEscape(FormatTuneText(report))
      << "</pre>\n"
      << "</body>\n</html>\n";
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + html_path + ": the disk may be full");
}

}  // namespace hiltwin::analysis
