#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "hiltwin/report_kit/gnuplot.h"
#include "jitter_format.h"
#include "plot_series.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;
using detail::GnuplotQuote;

constexpr std::size_t kMaxTimelinePoints = 20000;
constexpr std::size_t kPngStripBins = 300;  // 3.5 px each on the 1200 px picture
using detail::kDeadline;
using detail::kPurple;
using detail::kRed;
constexpr std::size_t kMaxHistogramBins = 120;
constexpr const char* kTerminal = "set terminal pngcairo size 1200,700 font 'sans,11' noenhanced\n";

void CheckWritten(const std::ofstream& out, const fs::path& path) {
  if (!out) throw PlotError("cannot write gnuplot's input " + path.string());
}

// Marker lines: the percentiles dashed; the deadline solid, so that it shows beside a p50
// that falls on it. Every key is opaque and drawn after the plots, so no line crosses it.
constexpr const char* kDashed = "dt 2 lw 1.5";
constexpr const char* kSolid = "dt 1 lw 2";

// A vertical line at x (first axis), behind the (translucent) bars, named in the key by
// MarkerKey.
std::string Marker(double x_us, const char* colour, const char* style = kDashed) {
  return "set arrow from " + std::to_string(x_us) + ", graph 0 to " + std::to_string(x_us) +
         ", graph 1 nohead " + style + " lc rgb '" + colour + "'\n";
}
std::string MarkerKey(const std::string& label, const char* colour, const char* style = kDashed) {
  return ", NaN with lines " + std::string(style) + " lc rgb '" + colour + "' title " +
         GnuplotQuote(label);
}

std::string DeadlineKey(const JitterReport& r) {
  return MarkerKey("deadline " + detail::FormatDuration(r.deadline_ns), kDeadline, kSolid);
}

// The deadline across a timeline panel: a constant plotted after the cycles, so that it shows
// over a dense band of 20,000 of them (an arrow would cross the key).
std::string DeadlinePlot(const JitterReport& r) {
  std::ostringstream plot;
  plot << ", " << static_cast<double>(r.deadline_ns) / 1e3 << " with lines " << kSolid
       << " lc rgb '" << kDeadline << "' title "
       << GnuplotQuote("deadline " + detail::FormatDuration(r.deadline_ns));
  return plot.str();
}

void HistogramPng(const JitterReport& r, const fs::path& scratch, const std::string& png) {
  const fs::path data = scratch / "histogram.dat";
  detail::LogRange x;
  x.Add(static_cast<double>(r.deadline_ns) / 1e3);  // the deadline is always on the picture
  {
    std::ofstream out(data);
    out << "# low_us high_us count\n";
    for (const HistogramBin& b : detail::LogDisplayBins(r.latency, kMaxHistogramBins)) {
      const double low = static_cast<double>(std::max<std::int64_t>(b.low_ns, 1)) / 1e3;
      const double high = static_cast<double>(std::max<std::int64_t>(b.high_ns, 2)) / 1e3;
      out << low << ' ' << high << ' ' << b.count << '\n';
      x.Add(low);
      x.Add(high);
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
       << "set ylabel 'cycles (log scale)'\nset yrange [0.5:*]\nset key top right opaque\n"
       << "set xrange [" << x.Low() << ":" << x.High() << "]\n"
       << Marker(static_cast<double>(s.p50_ns) / 1e3, "#2ca02c")
       << Marker(static_cast<double>(s.p99_ns) / 1e3, "#ff7f0e")
       << Marker(static_cast<double>(s.p999_ns) / 1e3, "#d62728")
       << Marker(static_cast<double>(r.deadline_ns) / 1e3, kDeadline, kSolid)
       << "plot " << GnuplotQuote(data.string())
       << " using (sqrt($1*$2)):3:1:2:(0.5):3 with boxxyerror fs transparent solid 0.6 "
       << "lc rgb '#1f77b4' "
       << "title 'cycles per bin'"
       << MarkerKey("p50 " + detail::FormatDuration(s.p50_ns), "#2ca02c")
       << MarkerKey("p99 " + detail::FormatDuration(s.p99_ns), "#ff7f0e")
       << MarkerKey("p99.9 " + detail::FormatDuration(s.p999_ns), "#d62728")
       << DeadlineKey(r) << "\n"
       << "set output\n";
    CheckWritten(gp, script);
  }
  detail::RenderWithGnuplot(script, png);
}

// timeline.dat (every cycle, thinned), misses.dat (the misses while few enough to mark),
// strip.dat (cycles and misses per time bin); the ranges of the two log panels.
struct TimelineData {
  fs::path cycles, misses, strip;
  bool marked = false;  // misses.dat holds the misses
  detail::LogRange latency, response;
};

TimelineData WriteTimelineData(const JitterReport& r, const TimingTrace& trace,
                               const fs::path& scratch) {
  TimelineData d;
  d.cycles = scratch / "timeline.dat";
  d.misses = scratch / "misses.dat";
  d.strip = scratch / "strip.dat";
  const double deadline_us = static_cast<double>(r.deadline_ns) / 1e3;
  d.latency.Add(deadline_us);
  d.response.Add(deadline_us);
  std::ofstream cycles(d.cycles);
  cycles << "# t_s latency_us compute_us response_us\n";
  cycles.precision(10);
  for (const detail::PlotPoint& p : detail::ThinnedCycles(trace, kMaxTimelinePoints)) {
    cycles << p.t_s << ' ' << p.latency_us << ' ' << p.compute_us << ' ' << p.response_us << '\n';
    d.latency.Add(p.latency_us);
    d.response.Add(p.compute_us);
    d.response.Add(p.response_us);
  }
  CheckWritten(cycles, d.cycles);
  const std::vector<detail::PlotPoint> marked = detail::MissMarkers(trace);
  d.marked = !marked.empty();
  if (d.marked) {
    std::ofstream misses(d.misses);
    misses << "# t_s response_us\n";
    misses.precision(10);
    for (const detail::PlotPoint& p : marked) misses << p.t_s << ' ' << p.response_us << '\n';
    CheckWritten(misses, d.misses);
  }
  std::ofstream strip(d.strip);
  strip << "# from_s to_s cycles missed\n";
  strip.precision(10);
  for (const detail::StripBin& b : detail::MissStrip(trace, kPngStripBins)) {
    strip << b.from_s << ' ' << b.to_s << ' ' << b.cycles << ' ' << b.missed << '\n';
  }
  CheckWritten(strip, d.strip);
  return d;
}

// Panels of the timeline, top to bottom, each placed on the page so their x axes line up.
std::string PanelAt(double top, double bottom) {
  std::ostringstream at;
  at << "set tmargin at screen " << top << "\nset bmargin at screen " << bottom << "\n";
  return at.str();
}

// The strip: the share of the cycles released in each time bin that missed.
std::string StripPanel(const JitterReport& r, const TimelineData& d) {
  std::string gp = PanelAt(0.90, 0.84) +
                   "set yrange [0:100]\nset ytics (0, 100)\nset format x ''\nunset key\n"
                   "set ylabel 'missed [%]'\nset style fill solid 0.9 noborder\n";
  if (r.misses == 0) gp += "set label 1 'no deadline miss' at graph 0.5, graph 0.5 center\n";
  gp += "plot " + GnuplotQuote(d.strip.string()) +
        " using (($1+$2)/2):($3 > 0 ? 100.0*$4/$3 : NaN):($2-$1) with boxes lc rgb '" + kRed +
        "' notitle\nunset label 1\n";
  return gp;
}

std::string LogPanel(const detail::LogRange& range, const std::string& ylabel) {
  std::ostringstream gp;
  gp << "set logscale y\nset yrange [" << range.Low() << ":" << range.High() << "]\n"
     << "set ytics autofreq\nset key top right opaque\nset ylabel " << GnuplotQuote(ylabel) << "\n";
  return gp.str();
}

std::string LatencyPanel(const JitterReport& r, const TimelineData& d) {
  return PanelAt(0.82, 0.50) + LogPanel(d.latency, "wake-up latency [us]") + "plot " +
         GnuplotQuote(d.cycles.string()) + " using 1:2 with lines lc rgb '" + detail::kBlue +
         "' title 'wake-up latency'" + DeadlinePlot(r) + "\n";
}

// Response against the deadline, the misses marked at their response (or, when too many to
// mark, a key entry pointing at the strip).
std::string ResponsePanel(const JitterReport& r, const TimelineData& d) {
  const std::string cycles = GnuplotQuote(d.cycles.string());
  std::string misses;
  if (d.marked) {
    misses = ", " + GnuplotQuote(d.misses.string()) +
             " using 1:2 with points pt 7 ps 0.8 lc rgb '" + kRed + "' title 'deadline miss'";
  } else if (r.misses > 0) {
    misses = ", NaN with boxes fs solid lc rgb '" + std::string(kRed) +
             "' title 'misses: too many to mark, see the strip above'";
  }
  return PanelAt(0.48, 0.09) +
         "set format x '% g'\nset xlabel 'time since the first release [s]'\n" +
         LogPanel(d.response, "response and compute [us]") + "plot " + cycles +
         " using 1:4 with lines lc rgb '" + kPurple + "' title 'response (release to end)', " +
         cycles + " using 1:3 with lines lc rgb '" + detail::kGreen + "' title 'compute'" +
         DeadlinePlot(r) + misses + "\n";
}

void TimelinePng(const JitterReport& r, const TimingTrace& trace, const fs::path& scratch,
                 const std::string& png) {
  const TimelineData d = WriteTimelineData(r, trace, scratch);
  const fs::path script = scratch / "timeline.gp";
  {
    std::ofstream gp(script);
    gp << "set terminal pngcairo size 1200,800 font 'sans,11' noenhanced\n"
       << "set output " << GnuplotQuote(png) << "\n"
       << "set multiplot title "
       << GnuplotQuote(std::to_string(r.cycles) + " cycles, " + std::to_string(r.misses) +
                       " deadline misses; top: the share of cycles missed over time")
       << "\nset grid\nset lmargin at screen 0.08\nset rmargin at screen 0.97\n"
       << "set xrange [0:" << std::max(detail::TraceSpanS(trace), 1e-6) << "]\n"
       << StripPanel(r, d) << LatencyPanel(r, d) << ResponsePanel(r, d)
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

// A double-quoted field of gnuplot's data (a name holding a double quote gets a single one).
std::string DataQuote(std::string text) {
  std::replace(text.begin(), text.end(), '"', '\'');
  return '"' + text + '"';
}

// A tick step for counts up to `most`: 1, 2 or 5 times a power of ten, at most 8 steps.
std::uint64_t CountStep(std::uint64_t most) {
  for (std::uint64_t magnitude = 1;; magnitude *= 10) {
    for (const std::uint64_t m : {1U, 2U, 5U}) {
      if (most <= 8 * m * magnitude) return m * magnitude;
    }
  }
}

// The culprits' names broken before " (pid N)" (as detail::SplitCulprit does for the SVG),
// over their class.
constexpr const char* kCulpritTic =
    "wrap(s) = strstrt(s, ' (') > 0 ? "
    "s[1:strstrt(s, ' (') - 1].\"\\n\".s[strstrt(s, ' (') + 1:*] : s\n";

void CausesPng(const JitterReport& r, const fs::path& scratch, const std::string& png) {
  const std::vector<detail::CauseBar> bars = detail::CauseBars(r);
  const fs::path data = scratch / "causes.dat";
  {
    std::ofstream out(data);
    out << "# culprit class cycles misses\n";
    for (const detail::CauseBar& b : bars) {
      out << DataQuote(b.label) << ' ' << DataQuote(b.cause) << ' ' << b.cycles << ' ' << b.misses
          << '\n';
    }
    CheckWritten(out, data);
  }
  const fs::path script = scratch / "causes.gp";
  {
    std::ofstream gp(script);
    gp << kTerminal << "set output " << GnuplotQuote(png) << "\n"
       << "set title 'causes of the late cycles: the culprits of the most notable cycles "
          "(dominant cause per cycle), and their class'\n";
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
         << CountStep(most) << "\n"
         << "set ylabel 'notable cycles'\nset key top right\nset bmargin 6\n" << kCulpritTic
         << "plot " << d << " using 3:xtic(wrap(stringcolumn(1)).\"\\n\".stringcolumn(2)) lc rgb "
         << "'#1f77b4' title 'notable cycles', " << d
         << " using 4 lc rgb '#d62728' title 'of them misses'\n";
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
