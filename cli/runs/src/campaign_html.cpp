// `hiltwin test --html`: one page that needs nothing from elsewhere (inline CSS and SVG, no
// script, no link), so a CI server can keep it as an artifact and anyone can open it offline.
// Nothing on it depends on when it was written: two runs of a lockstep campaign give the same
// page but for the wall-clock times.

#include <algorithm>
#include <cmath>
#include <limits>

#include "campaign_text.h"
#include "hiltwin/report_kit/string_format.h"
#include "hiltwin/report_kit/svg_chart.h"
#include "hiltwin/runs/campaign_report.h"

namespace hiltwin::app {
namespace campaign_html {

using analysis::detail::Format;
using analysis::detail::HtmlEscape;

constexpr const char* kCampaignStyle =
    "table{border-collapse:collapse;font-size:13px;margin:8px 0}"
    "th,td{border:1px solid #ddd;padding:3px 8px;text-align:left}th{background:#f4f4f4}"
    "td.pass{background:#e6f4ea;color:#137333;font-weight:bold}"
    "td.fail{background:#fce8e6;color:#c5221f;font-weight:bold}"
    ".badge{font-size:13px;padding:1px 6px;border-radius:3px;color:#fff}"
    ".badge.ok{background:#137333}.badge.bad{background:#c5221f}"
    ".error{color:#c5221f;white-space:pre-wrap}";

constexpr const char* kSeriesColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd"};

std::string ResultCell(bool passed) {
  return passed ? "<td class=\"pass\">PASS</td>" : "<td class=\"fail\">FAIL</td>";
}

// The table's rows of one scenario: one per criterion; its error, or (no criteria) that it
// ran, as a row of its own so every scenario shows in the table.
std::string ScenarioRows(const ScenarioResult& scenario) {
  const std::string name_cell = "<td>" + HtmlEscape(scenario.name) + "</td>";
  std::string rows;
  if (!scenario.error.empty()) {
    rows += "<tr>" + name_cell +
            "<td colspan=\"3\" class=\"error\">error: " + HtmlEscape(scenario.error) + "</td>" +
            ResultCell(false) + "</tr>\n";
  } else if (scenario.criteria.empty()) {
    rows += "<tr>" + name_cell + "<td colspan=\"3\">no criteria: judged on having run</td>" +
            ResultCell(true) + "</tr>\n";
  }
  for (const CriterionResult& criterion : scenario.criteria) {
    rows += "<tr>" + name_cell + "<td>" + HtmlEscape(criterion.name) + "</td><td>" +
            HtmlEscape(campaign_text::Required(criterion)) + "</td><td>" +
            HtmlEscape(campaign_text::Measured(criterion)) + "</td>" +
            ResultCell(criterion.passed) + "</tr>\n";
  }
  return rows;
}

std::string CriteriaTable(const CampaignResult& result) {
  std::string table =
      "<table>\n<tr><th>scenario</th><th>criterion</th><th>required</th><th>measured</th>"
      "<th>result</th></tr>\n";
  for (const ScenarioResult& scenario : result.scenarios) table += ScenarioRows(scenario);
  return table + "</table>\n";
}

// The smallest and largest finite value of `values` (lo > hi when there is none).
void Extend(const std::vector<double>& values, double& lo, double& hi) {
  for (const double value : values) {
    if (!std::isfinite(value)) continue;
    lo = std::min(lo, value);
    hi = std::max(hi, value);
  }
}

analysis::detail::SvgAxis Axis(double lo, double hi, double margin_share, std::string label) {
  if (!(lo <= hi)) lo = hi = 0.0;
  if (hi - lo <= 0.0) {
    // A flat curve: a band around it, so it draws as a line in the middle.
    const double half = lo == 0.0 ? 1.0 : std::abs(lo) * 0.1;
    return {lo - half, hi + half, false, std::move(label)};
  }
  const double margin = (hi - lo) * margin_share;
  return {lo - margin, hi + margin, false, std::move(label)};
}

std::string PlotSvg(const ScenarioResult& scenario) {
  const ScenarioPlot& plot = scenario.plot;
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double t_lo = kInfinity, t_hi = -kInfinity, y_lo = kInfinity, y_hi = -kInfinity;
  Extend(plot.time_s, t_lo, t_hi);
  for (const PlotSeries& series : plot.series) Extend(series.values, y_lo, y_hi);
  const std::string y_label = plot.y_unit.empty() ? "value" : "value (" + plot.y_unit + ")";
  analysis::detail::SvgChart chart(900, 300, Axis(t_lo, t_hi, 0.0, "time (s)"),
                                   Axis(y_lo, y_hi, 0.05, y_label), scenario.name);
  chart.Axes();
  const std::size_t colours = std::size(kSeriesColours);
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    chart.Line(plot.time_s, plot.series[i].values, kSeriesColours[i % colours]);
    chart.Legend(plot.series[i].name, kSeriesColours[i % colours]);
  }
  return chart.Finish();
}

bool HasPlot(const ScenarioPlot& plot) {
  return !plot.time_s.empty() &&
         std::any_of(plot.series.begin(), plot.series.end(),
                     [](const PlotSeries& series) { return !series.values.empty(); });
}

std::string ScenarioSection(const ScenarioResult& scenario) {
  const bool passed = scenario.passed();
  std::string html =
      "<h2>" + HtmlEscape(scenario.name) + " " +
      (passed ? "<span class=\"badge ok\">PASS</span>" : "<span class=\"badge bad\">FAIL</span>") +
      "</h2>\n";
  std::string facts = scenario.kind + ", " + scenario.clock + " clock";
  if (!scenario.controller.empty()) facts += ", controller " + scenario.controller;
  facts += ", exit code " + std::to_string(scenario.exit_code);
  if (!scenario.verdict.empty()) facts += ", verdict " + scenario.verdict;
  facts += ", " + campaign_text::WallTime(scenario.wall_s);
  html += "<p class=\"sub\">" + HtmlEscape(facts) + "</p>\n";
  if (!scenario.error.empty()) {
    html += "<p class=\"error\">error: " + HtmlEscape(scenario.error) + "</p>\n";
  }
  html += HasPlot(scenario.plot) ? PlotSvg(scenario)
                                 : "<p class=\"sub\">no plot: the scenario left no log</p>\n";
  return html;
}

std::string Heading(const CampaignResult& result) {
  const std::size_t failed = result.failed();
  std::string facts = result.file;
  if (!result.filter.empty()) facts += ", filter " + result.filter;
  const std::string shards = campaign_text::ShardsLabel(result);
  if (!shards.empty() && shards != "1/1") facts += ", shards " + shards;
  facts += Format(": %zu passed, %zu failed of %zu, ", result.scenarios.size() - failed, failed,
                  result.scenarios.size()) +
           campaign_text::WallTime(result.wall_s);
  return "<h1>hiltwin test: " + HtmlEscape(result.name) + "</h1>\n<p class=\"sub\">" +
         HtmlEscape(facts) + "</p>\n";
}

}  // namespace campaign_html

std::string ToHtml(const CampaignResult& result) {
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<title>hiltwin test: " + analysis::detail::HtmlEscape(result.name) + "</title>\n";
  html += std::string("<style>") + analysis::detail::kPageStyle + campaign_html::kCampaignStyle +
          "</style>\n</head>\n<body>\n";
  html += campaign_html::Heading(result);
  html += campaign_html::CriteriaTable(result);
  for (const ScenarioResult& scenario : result.scenarios) {
    html += campaign_html::ScenarioSection(scenario);
  }
  return html + "</body>\n</html>\n";
}

}  // namespace hiltwin::app
