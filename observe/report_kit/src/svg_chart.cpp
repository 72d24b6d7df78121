#include "hiltwin/report_kit/svg_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hiltwin::analysis::detail {
namespace {

std::string Num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

std::string TickText(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// Tick positions: powers of ten on a log axis (1-2-5 steps on a short one), 1-2-5 steps on a
// linear one.
std::vector<double> Ticks(const SvgAxis& axis) {
  std::vector<double> ticks;
  if (axis.log) {
    // Powers of ten; 1-2-5 steps when fewer than three of them fall in the range, so an axis
    // of one or two decades (2–75 us) still reads (and a marker at 50 sits on a tick).
    const double lo = std::floor(std::log10(std::max(axis.min, 1e-12)));
    const double hi = std::ceil(std::log10(std::max(axis.max, 1e-12)));
    for (const bool fine : {false, true}) {
      ticks.clear();
      for (double e = lo; e <= hi; e += 1.0) {
        for (const double m : {1.0, 2.0, 5.0}) {
          const double v = m * std::pow(10.0, e);
          if (m != 1.0 && !fine) continue;
          if (v >= axis.min * 0.999 && v <= axis.max * 1.001) ticks.push_back(v);
        }
      }
      if (ticks.size() >= 3) break;
    }
    return ticks;
  }
  const double span = axis.max - axis.min;
  if (!(span > 0.0)) return {axis.min};
  const double raw = span / 6.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * magnitude;
    if (step >= raw) break;
  }
  if (axis.integer) step = std::max(step, 1.0);
  for (double v = std::ceil(axis.min / step) * step; v <= axis.max + step * 1e-9; v += step) {
    ticks.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
  }
  return ticks;
}

double Fraction(const SvgAxis& axis, double v) {
  if (axis.log) {
    const double lo = std::log10(std::max(axis.min, 1e-12));
    const double hi = std::log10(std::max(axis.max, axis.min * 10.0));
    return (std::log10(std::max(v, 1e-12)) - lo) / std::max(hi - lo, 1e-12);
  }
  return (v - axis.min) / std::max(axis.max - axis.min, 1e-12);
}

bool Drawable(const SvgAxis& axis, double v) { return std::isfinite(v) && (!axis.log || v > 0.0); }

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

SvgChart::SvgChart(int width_px, int height_px, SvgAxis x, SvgAxis y, const std::string& title,
                   double strip_px)
    : width_px_(width_px), height_px_(height_px), x_(std::move(x)), y_(std::move(y)),
      strip_px_(std::max(strip_px, 0.0)), top_(strip_px_ > 0.0 ? 30.0 + strip_px_ + 8.0 : 30.0) {
  body_ += "<text x=\"" + Num(width_px_ / 2.0) + "\" y=\"18\" text-anchor=\"middle\" class=\"title\">" +
           HtmlEscape(title) + "</text>\n";
}

double SvgChart::Px(double x) const {
  return left_ + std::clamp(Fraction(x_, x), 0.0, 1.0) * (width_px_ - left_ - right_);
}

double SvgChart::Py(double y) const {
  return height_px_ - bottom_ - std::clamp(Fraction(y_, y), 0.0, 1.0) * (height_px_ - top_ - bottom_);
}

void SvgChart::Axes() {
  const double x0 = left_;
  const double x1 = width_px_ - right_;
  const double y0 = height_px_ - bottom_;
  const double y1 = top_;
  for (const double t : x_.ticks ? Ticks(x_) : std::vector<double>{}) {
    body_ += "<line class=\"grid\" x1=\"" + Num(Px(t)) + "\" y1=\"" + Num(y0) + "\" x2=\"" +
             Num(Px(t)) + "\" y2=\"" + Num(y1) + "\"/><text x=\"" + Num(Px(t)) + "\" y=\"" +
             Num(y0 + 16) + "\" text-anchor=\"middle\">" + TickText(t) + "</text>\n";
  }
  for (const double t : y_.ticks ? Ticks(y_) : std::vector<double>{}) {
    body_ += "<line class=\"grid\" x1=\"" + Num(x0) + "\" y1=\"" + Num(Py(t)) + "\" x2=\"" +
             Num(x1) + "\" y2=\"" + Num(Py(t)) + "\"/><text x=\"" + Num(x0 - 6) + "\" y=\"" +
             Num(Py(t) + 4) + "\" text-anchor=\"end\">" + TickText(t) + "</text>\n";
  }
  body_ += "<rect class=\"frame\" x=\"" + Num(x0) + "\" y=\"" + Num(y1) + "\" width=\"" +
           Num(x1 - x0) + "\" height=\"" + Num(y0 - y1) + "\"/>\n";
  body_ += "<text x=\"" + Num((x0 + x1) / 2) + "\" y=\"" + Num(height_px_ - 12.0) +
           "\" text-anchor=\"middle\">" + HtmlEscape(x_.label) + "</text>\n";
  body_ += "<text transform=\"translate(16," + Num((y0 + y1) / 2) +
           ") rotate(-90)\" text-anchor=\"middle\">" + HtmlEscape(y_.label) + "</text>\n";
}

void SvgChart::Bar(double x0, double x1, double y0, double y1, const char* colour) {
  const double px0 = Px(x0);
  const double px1 = Px(x1);
  const double py0 = Py(y0);
  const double py1 = Py(y1);
  body_ += "<rect x=\"" + Num(std::min(px0, px1)) + "\" y=\"" + Num(std::min(py0, py1)) +
           "\" width=\"" + Num(std::max(std::abs(px1 - px0), 1.0)) + "\" height=\"" +
           Num(std::abs(py1 - py0)) + "\" fill=\"" + colour + "\"/>\n";
}

void SvgChart::Line(const std::vector<double>& xs, const std::vector<double>& ys,
                    const char* colour) {
  std::string points;
  auto flush = [&] {
    if (!points.empty()) {
      body_ += "<polyline fill=\"none\" stroke-width=\"1\" stroke=\"" + std::string(colour) +
               "\" points=\"" + points + "\"/>\n";
    }
    points.clear();
  };
  for (std::size_t i = 0; i < xs.size() && i < ys.size(); ++i) {
    if (!Drawable(x_, xs[i]) || !Drawable(y_, ys[i])) {
      flush();
      continue;
    }
    points += Num(Px(xs[i])) + "," + Num(Py(ys[i])) + " ";
  }
  flush();
}

void SvgChart::Dots(const std::vector<double>& xs, const std::vector<double>& ys,
                    const char* colour) {
  for (std::size_t i = 0; i < xs.size() && i < ys.size(); ++i) {
    if (!Drawable(x_, xs[i]) || !Drawable(y_, ys[i])) continue;
    body_ += "<circle cx=\"" + Num(Px(xs[i])) + "\" cy=\"" + Num(Py(ys[i])) + "\" r=\"3\" fill=\"" +
             colour + "\"/>\n";
  }
}

void SvgChart::VerticalMarker(double x, const std::string& label, const char* colour) {
  if (!Drawable(x_, x)) return;
  const std::string px = Num(Px(x));
  body_ += "<line class=\"marker\" stroke=\"" + std::string(colour) + "\" x1=\"" + px + "\" y1=\"" +
           Num(top_) + "\" x2=\"" + px + "\" y2=\"" + Num(height_px_ - bottom_) + "\"/>\n";
  if (label.empty()) return;
  body_ += "<text fill=\"" + std::string(colour) + "\" transform=\"translate(" + Num(Px(x) - 4) +
           "," + Num(top_ + 4) + ") rotate(-90)\" text-anchor=\"end\">" + HtmlEscape(label) +
           "</text>\n";
}

void SvgChart::HorizontalMarker(double y, const std::string& label, const char* colour) {
  if (!Drawable(y_, y)) return;
  const std::string py = Num(Py(y));
  body_ += "<line class=\"marker\" stroke=\"" + std::string(colour) + "\" x1=\"" + Num(left_) +
           "\" y1=\"" + py + "\" x2=\"" + Num(width_px_ - right_) + "\" y2=\"" + py + "\"/>" +
           "<text class=\"halo\" fill=\"" + colour + "\" x=\"" + Num(left_ + 4) + "\" y=\"" +
           Num(Py(y) - 4) + "\">" + HtmlEscape(label) + "</text>\n";
}

void SvgChart::Label(double x, double y, const std::string& text, const char* anchor) {
  body_ += "<text x=\"" + Num(Px(x)) + "\" y=\"" + Num(Py(y) - 4.0) + "\" text-anchor=\"" + anchor +
           "\">" + HtmlEscape(text) + "</text>\n";
}

void SvgChart::Note(const std::string& text) {
  body_ += "<text x=\"" + Num(width_px_ / 2.0) + "\" y=\"" + Num(height_px_ / 2.0) +
           "\" text-anchor=\"middle\" class=\"note\">" + HtmlEscape(text) + "</text>\n";
}

void SvgChart::XCategory(double x, const std::string& text, int line) {
  body_ += "<text x=\"" + Num(Px(x)) + "\" y=\"" + Num(height_px_ - bottom_ + 16.0 + 14.0 * line) +
           "\" text-anchor=\"middle\">" + HtmlEscape(text) + "</text>\n";
}

void SvgChart::Strip(const std::vector<StripBar>& bars, const std::string& label,
                     const char* colour) {
  if (!(strip_px_ > 0.0)) return;
  const double bottom = top_ - 8.0;
  body_ += "<rect class=\"frame\" x=\"" + Num(left_) + "\" y=\"" + Num(bottom - strip_px_) +
           "\" width=\"" + Num(width_px_ - left_ - right_) + "\" height=\"" + Num(strip_px_) +
           "\"/><text x=\"" + Num(left_ - 6) + "\" y=\"" + Num(bottom - strip_px_ / 2 + 4) +
           "\" text-anchor=\"end\">" + HtmlEscape(label) + "</text>\n";
  for (const StripBar& b : bars) {
    if (!(b.fill > 0.0) || !Drawable(x_, b.x0) || !Drawable(x_, b.x1)) continue;
    const double height = std::min(b.fill, 1.0) * strip_px_;
    body_ += "<rect class=\"strip\" x=\"" + Num(Px(b.x0)) + "\" y=\"" + Num(bottom - height) +
             "\" width=\"" + Num(std::max(Px(b.x1) - Px(b.x0), 1.0)) + "\" height=\"" +
             Num(height) + "\" fill=\"" + colour + "\"/>\n";
  }
}

void SvgChart::Legend(const std::string& text, const char* colour, bool dashed) {
  const double y = top_ + 14.0 + 16.0 * legend_entries_++;
  const double x = width_px_ - right_ - 10.0;
  // A white backing, about as wide as the text (6.2 px a character at 11 px), so dense data
  // under the legend does not cross it.
  const double width = 6.2 * static_cast<double>(text.size()) + (dashed ? 24 : 14) + 6;
  body_ += "<rect fill=\"#fff\" fill-opacity=\"0.85\" x=\"" + Num(x - width) + "\" y=\"" +
           Num(y - 12) + "\" width=\"" + Num(width + 4) + "\" height=\"16\"/>";
  if (dashed) {
    body_ += "<line class=\"marker\" stroke=\"" + std::string(colour) + "\" x1=\"" + Num(x - 18) +
             "\" y1=\"" + Num(y - 4) + "\" x2=\"" + Num(x) + "\" y2=\"" + Num(y - 4) + "\"/>";
  } else {
    body_ += "<rect x=\"" + Num(x - 8) + "\" y=\"" + Num(y - 8) +
             "\" width=\"8\" height=\"8\" fill=\"" + colour + "\"/>";
  }
  body_ += "<text x=\"" + Num(x - (dashed ? 24 : 14)) + "\" y=\"" + Num(y) +
           "\" text-anchor=\"end\">" + HtmlEscape(text) + "</text>\n";
}

std::string SvgChart::Finish() const {
  return "<svg width=\"" + std::to_string(width_px_) + "\" height=\"" + std::to_string(height_px_) +
         "\" viewBox=\"0 0 " + std::to_string(width_px_) + " " + std::to_string(height_px_) +
         "\" role=\"img\">\n" + body_ + "</svg>\n";
}

}  // namespace hiltwin::analysis::detail
