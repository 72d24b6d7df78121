#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "hiltwin/report_kit/gnuplot.h"
#include "jitter_format.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;
using detail::GnuplotQuote;

constexpr std::size_t kMaxTimelinePoints = 20000;
constexpr std::size_t kMaxHistogramBins = 120;
constexpr const char* kTerminal = "set terminal pngcairo size 1200,700 font 'sans,11' noenhanced\n";

void CheckWritten(const std::ofstream& out, const fs::path& path) {
  if (!out) throw PlotError("cannot write gnuplot's input " + path.string());
}

// A dashed vertical line at x (first axis), named in the key by MarkerKey.
std::string Marker(double x_us, const char* colour) {
  return "set arrow from " + std::to_string(x_us) + ", graph 0 to " + std::to_string(x_us) +
         ", graph 1 nohead dt 2 lw 1.5 lc rgb '" + colour + "'\n";
}
std::string MarkerKey(const std::string& label, const char* colour) {
  return ", NaN with lines dt 2 lw 1.5 lc rgb '" + std::string(colour) + "' title " +
         GnuplotQuote(label);
}

void HistogramPng(const JitterReport& r, const fs::path& scratch, const std::string& png) {
  const fs::path data = scratch / "histogram.dat";
  {
    std::ofstream out(data);
    out << "# low_us high_us count\n";
    for (const HistogramBin& b : detail::LogDisplayBins(r.latency, kMaxHistogramBins)) {
      const double low = static_cast<double>(std::max<std::int64_t>(b.low_ns, 1)) / 1e3;
      const double high = static_cast<double>(std::max<std::int64_t>(b.high_ns, 2)) / 1e3;
      out << low << ' ' << high << ' ' << b.count << '\n';
    }
    if (r.latency.bins.empty()) out << "1 2 0\n";
    CheckWritten(out, data);
  }
  const fs::path script = scratch / "histogram.gp";
  {
    std::ofstream gp(script);
    const scheduler::TimingSummary& s = r.latency.summary;
    gp << kTerminal << "set output " << GnuplotQuote(png) << "\n"
       << "set title " << GnuplotQuote("wake-up latency, " + std::to_string(s.count) + " cycles") << "\n"
       << "set logscale xy\nset grid\nset xlabel 'wake-up latency [us]'\n"
       << "set ylabel 'cycles (log scale)'\nset yrange [0.5:*]\nset key top right\n"
       << Marker(static_cast<double>(s.p50_ns) / 1e3, "#2ca02c")
       << Marker(static_cast<double>(s.p99_ns) / 1e3, "#ff7f0e")
       << Marker(static_cast<double>(s.p999_ns) / 1e3, "#d62728")
       << "plot " << GnuplotQuote(data.string())
       << " using (sqrt($1*$2)):3:1:2:(0.5):3 with boxxyerror fs solid 0.6 lc rgb '#1f77b4' "
       << "title 'cycles per bin'"
       << MarkerKey("p50 " + detail::FormatDuration(s.p50_ns), "#2ca02c")
       << MarkerKey("p99 " + detail::FormatDuration(s.p99_ns), "#ff7f0e")
       << MarkerKey("p99.9 " + detail::FormatDuration(s.p999_ns), "#d62728") << "\n"
       << "set output\n";
    CheckWritten(gp, script);
  }
  detail::RenderWithGnuplot(script, png);
}

void TimelinePng(const JitterReport& r, const TimingTrace& trace, const fs::path& scratch,
                 const std::string& png) {
  const fs::path data = scratch / "timeline.dat";
  {
    std::ofstream out(data);
    out << "# t_s latency_us compute_us missed\n";
    out.precision(10);
    for (const detail::PlotPoint& p : detail::ThinnedCycles(trace, kMaxTimelinePoints)) {
      out << p.t_s << ' ' << p.latency_us << ' ' << p.compute_us << ' ' << (p.missed ? 1 : 0) << '\n';
    }
    CheckWritten(out, data);
  }
  const fs::path script = scratch / "timeline.gp";
  {
    std::ofstream gp(script);
    const std::string d = GnuplotQuote(data.string());
    const double deadline_us = static_cast<double>(r.deadline_ns) / 1e3;
    gp << kTerminal << "set output " << GnuplotQuote(png) << "\n"
       << "set multiplot layout 2,1 title "
       << GnuplotQuote(std::to_string(r.cycles) + " cycles, " + std::to_string(r.misses) +
                       " deadline misses (red)") << "\n"
       << "set grid\nset logscale y\nset autoscale xfix\nset lmargin 12\nset key top right\n"
       << "set ylabel 'latency [us]'\n"
       << "plot " << d << " using 1:2 with lines lc rgb '#1f77b4' title 'wake-up latency', "
       << d << " using 1:($4 > 0 ? $2 : NaN) with points pt 7 ps 0.8 lc rgb '#d62728' title 'miss'\n"
       << "set xlabel 'time since the first release [s]'\nset ylabel 'compute [us]'\n"
       << "set arrow from graph 0, first " << deadline_us << " to graph 1, first " << deadline_us
       << " nohead dt 2 lc rgb '#7f7f7f'\n"
       << "plot " << d << " using 1:3 with lines lc rgb '#2ca02c' title 'compute', " << d
       << " using 1:($4 > 0 ? $3 : NaN) with points pt 7 ps 0.8 lc rgb '#d62728' title 'miss', "
       << "NaN with lines dt 2 lc rgb '#7f7f7f' title 'deadline'\n"
       << "unset multiplot\nset output\n";
    CheckWritten(gp, script);
  }
  detail::RenderWithGnuplot(script, png);
}

}  // namespace

namespace {

// A picture holding one line of text where a chart would be.
std::string TextOnly(const std::string& text) {
  return "unset border\nunset tics\nunset key\nset xrange [0:1]\nset yrange [0:1]\n"
         "set label 1 " + GnuplotQuote(text) + " at 0.5,0.5 center font 'sans,16'\n"
         "plot NaN notitle\n";
}

// The one-line note without the backquotes of the text report (gnuplot substitutes them).
std::string NotRecordedNote() {
  std::string note = detail::kCausesNotRecorded;
  note.erase(std::remove(note.begin(), note.end(), '`'), note.end());
  return note;
}

void CausesPng(const JitterReport& r, const fs::path& scratch, const std::string& png) {
  const std::vector<detail::CauseBar> bars = detail::CauseBars(r);
  const fs::path data = scratch / "causes.dat";
  {
    std::ofstream out(data);
    out << "# class cycles misses\n";
    for (const detail::CauseBar& b : bars) out << b.label << ' ' << b.cycles << ' ' << b.misses << '\n';
    CheckWritten(out, data);
  }
  const fs::path script = scratch / "causes.gp";
  {
    std::ofstream gp(script);
    gp << kTerminal << "set output " << GnuplotQuote(png) << "\n"
       << "set title 'causes of the late cycles (dominant cause per notable cycle)'\n";
    if (!r.kernel_recorded) {
      gp << TextOnly(NotRecordedNote());
    } else if (bars.empty()) {
      gp << TextOnly("no notable cycle: no miss and no wake-up above p99.9");
    } else {
      const std::string d = GnuplotQuote(data.string());
      std::uint64_t most = 1;
      for (const detail::CauseBar& b : bars) most = std::max(most, b.cycles);
      gp << "set style data histograms\nset style histogram clustered gap 1\n"
         << "set style fill solid 0.7 border -1\nset boxwidth 0.9\nset grid ytics\n"
         << "set yrange [0:" << static_cast<double>(most) * 1.25 << "]\nset ytics "
         << std::max<std::uint64_t>(1, (most + 7) / 8) << "\n"
         << "set ylabel 'notable cycles'\nset key top right\n"
         << "plot " << d << " using 2:xtic(1) lc rgb '#1f77b4' title 'notable cycles', " << d
         << " using 3 lc rgb '#d62728' title 'of them misses'\n";
    }
    gp << "set output\n";
    CheckWritten(gp, script);
  }
  detail::RenderWithGnuplot(script, png);
}

}  // namespace

std::vector<std::string> WriteJitterPlots(const JitterReport& report, const TimingTrace& trace,
                                          const std::string& dir) {
  const detail::ScratchDir scratch("hiltwin-jitter");
  const fs::path out_dir(dir);
  const std::string histogram = (out_dir / "jitter_latency_histogram.png").string();
  const std::string timeline = (out_dir / "jitter_timeline.png").string();
  const std::string causes = (out_dir / "jitter_causes.png").string();
  HistogramPng(report, scratch.path(), histogram);
  TimelinePng(report, trace, scratch.path(), timeline);
  CausesPng(report, scratch.path(), causes);
  return {histogram, timeline, causes};
}

}  // namespace hiltwin::analysis
