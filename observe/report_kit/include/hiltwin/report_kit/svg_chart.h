#pragma once
/// Just enough SVG for the HTML pages of the jitter report and
/// of `hiltwin tune` (axes with linear or log scales, bars, lines, dots, text), written inline
/// so a page needs nothing from outside: no script, no font, no link.

#include <string>
#include <vector>

namespace hiltwin::analysis::detail {

/// The CSS every analysis HTML page shares: the page, its headings, the charts' classes and
/// the preformatted text report.
inline constexpr const char* kPageStyle =
    "body{font-family:sans-serif;margin:24px auto;max-width:960px;color:#222;background:#fff}"
    "h1{font-size:22px;margin-bottom:4px}h2{font-size:17px;margin-top:28px}"
    ".sub{color:#666;margin-top:0}"
    "svg{border:1px solid #eee;margin:6px 0;font-size:11px;fill:#222}"
    "svg .grid{stroke:#eee}svg .frame{fill:none;stroke:#888}"
    "svg .marker{stroke-dasharray:4 3;stroke-width:1.5}"
    "svg .title{font-size:14px;font-weight:bold}svg .note{font-size:15px;fill:#666}"
    "svg .halo{paint-order:stroke;stroke:#fff;stroke-width:3px;stroke-linejoin:round}"
    "pre{background:#f7f7f7;border:1px solid #e5e5e5;padding:12px;font-size:12px;overflow-x:auto}";

/// Escapes &, <, >, " for HTML and SVG text.
[[nodiscard]] std::string HtmlEscape(const std::string& text);

/// One axis: range, scale and label.
struct SvgAxis {
  double min = 0.0;
  double max = 1.0;
  bool log = false;
  std::string label;
  bool ticks = true;     ///< false: a categorical axis, labelled by the caller (XCategory)
  bool integer = false;  ///< counts: ticks at whole numbers only
};

/// One bar of a strip (SvgChart::Strip): an x range and the share of the strip's height it
/// fills, 0 to 1.
struct StripBar {
  double x0 = 0.0;
  double x1 = 0.0;
  double fill = 0.0;
};

/// A chart area of a fixed pixel size; data coordinates map through the axes.
class SvgChart {
 public:
  /// `strip_px` > 0 reserves a lane of that height between the title and the plot area, on
  /// the same x axis (Strip).
  SvgChart(int width_px, int height_px, SvgAxis x, SvgAxis y, const std::string& title,
           double strip_px = 0.0);

  /// Grid, ticks, tick labels and axis labels.
  void Axes();
  /// A filled rectangle between data coordinates (x0, y0) and (x1, y1).
  void Bar(double x0, double x1, double y0, double y1, const char* colour);
  /// A polyline through the points (NaN or, on a log axis, values ≤ 0 break the line).
  void Line(const std::vector<double>& xs, const std::vector<double>& ys, const char* colour);
  /// A dot at each point.
  void Dots(const std::vector<double>& xs, const std::vector<double>& ys, const char* colour);
  /// A dashed vertical (x) or horizontal (y) marker with a label ("" for none: say it in the
  /// legend); a horizontal one's label has a white halo.
  void VerticalMarker(double x, const std::string& label, const char* colour);
  void HorizontalMarker(double y, const std::string& label, const char* colour);
  /// Text just above a data position (anchor "start", "middle", "end").
  void Label(double x, double y, const std::string& text, const char* anchor);
  /// A category's name under the x axis; `line` 1 is a second line under the first.
  void XCategory(double x, const std::string& text, int line = 0);
  /// Bars in the strip lane, from its bottom up (class "strip"), and its name left of it: a
  /// density over x that stays readable where markers in the plot would cover it.
  void Strip(const std::vector<StripBar>& bars, const std::string& label, const char* colour);
  /// Text centred in the plot area (for a chart with nothing to draw).
  void Note(const std::string& text);
  /// A legend entry (top right, one per call), a box or (dashed) a line, on a white backing
  /// so it reads over the data.
  void Legend(const std::string& text, const char* colour, bool dashed = false);

  /// The finished <svg> element.
  [[nodiscard]] std::string Finish() const;

  [[nodiscard]] double Px(double x) const;
  [[nodiscard]] double Py(double y) const;

 private:
  int width_px_;
  int height_px_;
  SvgAxis x_;
  SvgAxis y_;
  double left_ = 70.0;
  double right_ = 20.0;
  double strip_px_ = 0.0;
  double top_ = 30.0;
  double bottom_ = 50.0;
  int legend_entries_ = 0;
  std::string body_;
};

}  // namespace hiltwin::analysis::detail
