#include "hiltwin/assess/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "hiltwin/report_kit/gnuplot.h"

namespace hiltwin::analysis {
namespace {

// Rows to draw: all of them, or per bucket the rows with the smallest and largest difference
// (in time order), so spikes in the error survive thinning.
std::vector<std::size_t> RowsToDraw(const Assessment& a, std::size_t max_points) {
  const std::size_t n = a.t_s.size();
  std::vector<std::size_t> rows;
  if (n <= max_points || max_points < 4) {
    rows.resize(n);
    for (std::size_t i = 0; i < n; ++i) rows[i] = i;
    return rows;
  }
  const std::size_t buckets = max_points / 2;
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = b * n / buckets;
    const std::size_t end = (b + 1) * n / buckets;
    if (begin >= end) continue;
    std::size_t lo = begin;
    std::size_t hi = begin;
    for (std::size_t i = begin; i < end; ++i) {
      const double d = a.y_sim[i] - a.y_exp[i];
      if (d < a.y_sim[lo] - a.y_exp[lo]) lo = i;
      if (d > a.y_sim[hi] - a.y_exp[hi]) hi = i;
    }
    rows.push_back(std::min(lo, hi));
    if (lo != hi) rows.push_back(std::max(lo, hi));
  }
  return rows;
}

}  // namespace

void WritePlot(const Assessment& a, const std::string& png_path, std::size_t max_points) {
  const detail::ScratchDir dir("hiltwin-assess");
  const std::filesystem::path data = dir.path() / "curves.dat";
  const std::filesystem::path script = dir.path() / "plot.gp";
  {
    std::ofstream out(data);
    out << "# time y_sim y_exp diff diff_compensated\n";
    out.precision(12);
    for (const std::size_t i : RowsToDraw(a, max_points)) {
      const double comp = a.y_sim_compensated.size() > i ? a.y_sim_compensated[i]
                                                             : std::numeric_limits<double>::quiet_NaN();
      out << a.t_s[i] << ' ' << a.y_sim[i] << ' ' << a.y_exp[i] << ' ' << a.y_sim[i] - a.y_exp[i]
          << ' ';
      if (std::isfinite(comp)) {
        out << comp - a.y_exp[i];
      } else {
        out << "NaN";
      }
      out << '\n';
    }
    if (!out) throw PlotError("cannot write gnuplot's data file " + data.string());
  }
  char delay[64];
  std::snprintf(delay, sizeof delay, "%.4g ms", a.delay.delay_s * 1e3);
  char title[160];
  std::snprintf(title, sizeof title,
                "time-domain score %.6f raw, %.6f delay-compensated    total %.6f: %s",
                a.time.eta, a.time_compensated.eta, a.total, a.pass ? "PASS" : "FAIL");
  {
    std::ofstream gp(script);
    const std::string d = detail::GnuplotQuote(data.string());
    gp << "set terminal pngcairo size 1280,860 font 'sans,11' noenhanced\n"
       << "set output " << detail::GnuplotQuote(png_path) << "\n"
       << "set datafile missing 'NaN'\n"
       << "set multiplot layout 2,1 title " << detail::GnuplotQuote(title) << "\n"
       << "set grid\nset key outside top center horizontal\nset autoscale xfix\n"
       << "set lmargin 14\nset rmargin 4\n"
       << "set ylabel 'value'\n"
       << "plot " << d << " using 1:3 with lines lw 2 lc rgb '#2ca02c' title "
       << detail::GnuplotQuote("experiment y_e: " + a.exp_label) << ", \\\n     " << d
       << " using 1:2 with lines lw 1 dt 2 lc rgb '#d62728' title "
       << detail::GnuplotQuote("simulation y_s: " + a.sim_label) << "\n"
       << "set xlabel 'time [s]'\nset ylabel 'y_s - y_e'\n"
       << "plot " << d << " using 1:4 with lines lw 1 lc rgb '#1f77b4' title 'difference', \\\n     "
       << d << " using 1:5 with lines lw 1 lc rgb '#ff7f0e' title "
       << detail::GnuplotQuote("difference after delay compensation (d = " + std::string(delay) + ")")
       << "\nunset multiplot\nset output\n";
    if (!gp) throw PlotError("cannot write gnuplot's script " + script.string());
  }

  detail::RenderWithGnuplot(script, png_path);
}

}  // namespace hiltwin::analysis
