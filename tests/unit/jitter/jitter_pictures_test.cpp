// What the jitter pictures show, read back from the files: the deadline on the latency and
// response plots, misses at their response, a bounded number of miss markers at 20 kHz (a
// density strip instead), and the named culprits of the causes chart. The SVGs of the HTML page
// are parsed (coordinates checked against the chart's own tick labels); the gnuplot scripts and
// their data are captured by a gnuplot wrapper on PATH that copies them before rendering.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_fixtures.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;
using testing::MakeTracedRun;
using testing::ReadFile;
using testing::TempDir;
using testing::TracedRun;

constexpr const char* kRed = "#d62728";
constexpr double kDeadlineUs = 50.0;
// At most this many miss markers on a picture (tens of thousands of misses at 20 kHz).
constexpr std::size_t kMarkerBound = 100;

// ---- SVG, as the HTML page holds it ----

struct Element {
  std::map<std::string, std::string> attr;
  std::string text;  // of a <text>

  [[nodiscard]] double Num(const std::string& name) const {
    const auto it = attr.find(name);
    return it == attr.end() ? std::nan("") : std::strtod(it->second.c_str(), nullptr);
  }
  [[nodiscard]] std::string Attr(const std::string& name) const {
    const auto it = attr.find(name);
    return it == attr.end() ? "" : it->second;
  }
};

// The n-th <svg> element of a page.
std::string NthSvg(const std::string& html, int n) {
  std::size_t at = html.find("<svg");
  for (int i = 0; i < n && at != std::string::npos; ++i) at = html.find("<svg", at + 1);
  if (at == std::string::npos) return "";
  return html.substr(at, html.find("</svg>", at) - at);
}

// Every <tag ...> of an SVG with its attributes (and, for <text>, what it says).
std::vector<Element> Elements(const std::string& svg, const std::string& tag) {
  std::vector<Element> out;
  const std::string open = "<" + tag + " ";
  for (std::size_t at = svg.find(open); at != std::string::npos; at = svg.find(open, at + 1)) {
    const std::size_t end = svg.find('>', at);
    Element e;
    std::istringstream attrs(svg.substr(at + open.size(), end - at - open.size()));
    std::string name;
    while (std::getline(attrs >> std::ws, name, '=')) {
      std::string value;
      attrs.ignore(1);  // the opening quote
      std::getline(attrs, value, '"');
      e.attr[name] = value;
    }
    if (tag == "text") e.text = svg.substr(end + 1, svg.find('<', end) - end - 1);
    out.push_back(std::move(e));
  }
  return out;
}

bool IsNumber(const std::string& s) {
  char* end = nullptr;
  (void)std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size();
}

// An axis recovered from two of its tick labels: data value -> pixel.
struct TickAxis {
  double v0 = 0, p0 = 0, v1 = 0, p1 = 0;
  bool log = false;
  [[nodiscard]] double Px(double v) const {
    const auto f = [&](double x) { return log ? std::log10(x) : x; };
    return p0 + (f(v) - f(v0)) / (f(v1) - f(v0)) * (p1 - p0);
  }
};

// x ticks: numeric labels centred under the plot; y ticks: numeric labels right-aligned left of
// it, 4 px below their grid line (SvgChart::Axes).
TickAxis AxisFromTicks(const std::string& svg, bool x_axis, bool log) {
  std::vector<std::pair<double, double>> ticks;
  for (const Element& t : Elements(svg, "text")) {
    if (!IsNumber(t.text)) continue;
    if (x_axis && t.Attr("text-anchor") == "middle" && !t.attr.count("transform")) {
      ticks.emplace_back(std::strtod(t.text.c_str(), nullptr), t.Num("x"));
    } else if (!x_axis && t.Attr("text-anchor") == "end") {
      ticks.emplace_back(std::strtod(t.text.c_str(), nullptr), t.Num("y") - 4.0);
    }
  }
  EXPECT_GE(ticks.size(), 2u) << (x_axis ? "x" : "y") << " ticks of\n" << svg;
  if (ticks.size() < 2) return {};
  return {ticks.front().first, ticks.front().second, ticks.back().first, ticks.back().second, log};
}

std::string HtmlOf(const JitterReport& r, const TimingTrace& trace, const TempDir& dir) {
  return ReadFile(WriteJitterHtml(r, trace, dir.str()));
}

// The dashed marker lines of a chart that run vertically (x1 == x2) or horizontally.
std::vector<Element> Markers(const std::string& svg, bool vertical) {
  std::vector<Element> out;
  for (const Element& l : Elements(svg, "line")) {
    if (l.Attr("class") != "marker") continue;
    const bool upright = l.Num("x1") == l.Num("x2") && l.Num("y1") != l.Num("y2");
    // Across the plot: a legend's short sample line is not a marker.
    const bool across = l.Num("y1") == l.Num("y2") && l.Num("x2") - l.Num("x1") > 100;
    if (vertical ? upright : across) out.push_back(l);
  }
  return out;
}

bool HasText(const std::string& svg, const std::string& what) {
  const std::vector<Element> texts = Elements(svg, "text");
  return std::any_of(texts.begin(), texts.end(),
                     [&](const Element& t) { return t.text.find(what) != std::string::npos; });
}

TEST(JitterPictures, LatencyHistogramSvgDrawsTheDeadlineWhereItIs) {
  const TracedRun run = MakeTracedRun();  // latencies 3–25 µs: the deadline lies beyond them
  const TempDir dir;
  const std::string svg = NthSvg(HtmlOf(AnalyzeJitter(run.trace, &run.kernel), run.trace, dir), 0);
  const TickAxis x = AxisFromTicks(svg, true, true);
  const std::vector<Element> markers = Markers(svg, true);
  const auto deadline = std::find_if(markers.begin(), markers.end(), [&](const Element& m) {
    return std::abs(m.Num("x1") - x.Px(kDeadlineUs)) < 0.2;
  });
  ASSERT_NE(deadline, markers.end()) << "no marker at x = " << x.Px(kDeadlineUs) << "\n" << svg;
  EXPECT_TRUE(HasText(svg, "deadline 50 us")) << svg;
}

TEST(JitterPictures, TimelineSvgMarksMissesAtTheirResponseAboveTheDeadline) {
  const TracedRun run = MakeTracedRun();
  const TempDir dir;
  const std::string svg = NthSvg(HtmlOf(AnalyzeJitter(run.trace, &run.kernel), run.trace, dir), 1);
  const TickAxis x = AxisFromTicks(svg, true, false);
  const TickAxis y = AxisFromTicks(svg, false, true);
  const std::vector<Element> lines = Markers(svg, false);
  ASSERT_EQ(lines.size(), 1u) << svg;
  EXPECT_NEAR(lines[0].Num("y1"), y.Px(kDeadlineUs), 0.2);
  std::vector<Element> dots = Elements(svg, "circle");
  dots.erase(std::remove_if(dots.begin(), dots.end(),
                            [](const Element& c) { return c.Attr("fill") != kRed; }),
             dots.end());
  ASSERT_EQ(dots.size(), 2u) << svg;  // k = 1000 and k = 3000
  // Each at its release time and response (compute 60 and 49 µs: the second below the line).
  const double want[2][2] = {{0.050, 63.1}, {0.150, 52.1}};
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_NEAR(dots[i].Num("cx"), x.Px(want[i][0]), 0.2) << i;
    EXPECT_NEAR(dots[i].Num("cy"), y.Px(want[i][1]), 0.2) << i;
    EXPECT_LT(dots[i].Num("cy"), lines[0].Num("y1")) << "miss " << i << " drawn below the deadline";
  }
  EXPECT_TRUE(HasText(svg, "response")) << svg;
}

// 3 s at 20 kHz: met for the first second, then every cycle wakes 55 µs late (past the 50 µs
// deadline) and skips the next release: 40,000 misses, 20,000 of them missed cycles.
TimingTrace Infeasible20kHz() {
  testing::RunSpec spec;
  spec.releases = 60'000;
  spec.latency_ns = [](std::uint64_t k) -> std::int64_t { return k < 20'000 ? 3'000 : 55'000; };
  spec.compute_ns = [](std::uint64_t) -> std::int64_t { return 5'000; };
  return testing::MakeTrace(spec);
}

std::size_t MissedCycles(const TimingTrace& trace) {
  return static_cast<std::size_t>(std::count_if(
      trace.cycles.begin(), trace.cycles.end(),
      [](const TracedCycle& c) { return c.sample.missed; }));
}

TEST(JitterPictures, TimelineSvgAt20kHzShowsMissesAsAStripNotTensOfThousandsOfDots) {
  const TimingTrace trace = Infeasible20kHz();
  ASSERT_EQ(MissedCycles(trace), 20'000u);
  const TempDir dir;
  const std::string svg = NthSvg(HtmlOf(AnalyzeJitter(trace, nullptr), trace, dir), 1);
  EXPECT_LE(Elements(svg, "circle").size(), kMarkerBound);
  std::vector<Element> strip = Elements(svg, "rect");
  strip.erase(std::remove_if(strip.begin(), strip.end(),
                             [](const Element& r) { return r.Attr("class") != "strip"; }),
              strip.end());
  ASSERT_FALSE(strip.empty()) << svg;
  EXPECT_LE(strip.size(), 1000u);
  // The strip shows where the misses are: from 1 s on, nowhere before.
  const TickAxis x = AxisFromTicks(svg, true, false);
  double covered = 0.0;
  for (const Element& r : strip) {
    EXPECT_GE(r.Num("x") + r.Num("width"), x.Px(1.0) - 0.2) << "a miss shown before 1 s";
    covered += r.Num("width");
  }
  EXPECT_GT(covered, 0.95 * (x.Px(3.0) - x.Px(1.0)));
}

// 21 misses, each a 40 µs interrupt in the step, by six handlers: irq-a 6 times, irq-b 5, ...
// irq-f once.
TracedRun ManyCulprits() {
  testing::RunSpec spec;
  spec.releases = 4'000;
  std::map<std::uint64_t, testing::SpecialCycle> special;
  const char* names[] = {"irq-a", "irq-b", "irq-c", "irq-d", "irq-e", "irq-f"};
  std::uint64_t k = 100;
  for (int n = 0; n < 6; ++n) {
    for (int i = 0; i < 6 - n; ++i, k += 100) {
      spec.overrides[k] = {3'000, 60'000};
      special[k] = [name = std::string(names[n]), irq = 40 + n](testing::KernelScript& script,
                                                               const scheduler::TimingSample& s) {
        testing::NormalCycle(script, s);
        script.Irq(s.start_ns + 1'000, s.start_ns + 41'000, testing::kLoopCpu, irq, name);
      };
    }
  }
  TracedRun run{testing::MakeTrace(spec), {}};
  run.kernel = testing::MakeKernel(run.trace, special);
  return run;
}

TEST(JitterPictures, CausesSvgNamesTheTopFiveCulpritsWithTheirClass) {
  const TracedRun run = ManyCulprits();
  const JitterReport r = AnalyzeJitter(run.trace, &run.kernel);
  ASSERT_EQ(r.notable.size(), 21u);
  const TempDir dir;
  const std::string svg = NthSvg(HtmlOf(r, run.trace, dir), 2);
  std::vector<double> at;
  for (const char* name : {"irq-a", "irq-b", "irq-c", "irq-d", "irq-e"}) {
    const std::vector<Element> texts = Elements(svg, "text");
    const auto it = std::find_if(texts.begin(), texts.end(),
                                 [&](const Element& t) { return t.text == name; });
    ASSERT_NE(it, texts.end()) << name << " not named\n" << svg;
    at.push_back(it->Num("x"));
  }
  EXPECT_TRUE(std::is_sorted(at.begin(), at.end())) << "most cycles first";
  EXPECT_FALSE(HasText(svg, "irq-f")) << "only the top five by name";
  EXPECT_TRUE(HasText(svg, "1 other culprit")) << svg;
  const std::vector<Element> texts = Elements(svg, "text");
  EXPECT_GE(std::count_if(texts.begin(), texts.end(),
                          [](const Element& t) { return t.text == "interrupt"; }),
            5);
  for (const char* count : {"6", "5", "4", "3", "2", "1"}) {  // above the bars, not the ticks
    EXPECT_TRUE(std::any_of(texts.begin(), texts.end(), [&](const Element& t) {
      return t.text == count && t.Attr("text-anchor") == "middle";
    })) << count;
  }
}

// ---- gnuplot: the scripts and data as gnuplot received them ----

// Puts a `gnuplot` first on PATH that copies its script's folder (the script and its data) into
// `captured` and then runs the real gnuplot; PATH is restored at the end.
class GnuplotCapture {
 public:
  explicit GnuplotCapture(const std::string& real_gnuplot) {
    fs::create_directories(bin_);
    fs::create_directories(captured_);
    const std::string wrapper = (bin_ / "gnuplot").string();
    std::ofstream(wrapper) << "#!/bin/sh\ncp \"$(dirname \"$1\")\"/* '" << captured_.string()
                           << "'/\nexec '" << real_gnuplot << "' \"$@\"\n";
    fs::permissions(wrapper, fs::perms::owner_all);
    const char* path = std::getenv("PATH");  // NOLINT(concurrency-mt-unsafe): test set-up
    old_path_ = path != nullptr ? path : "";
    setenv("PATH", (bin_.string() + ":" + old_path_).c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
  }
  ~GnuplotCapture() { setenv("PATH", old_path_.c_str(), 1); }  // NOLINT(concurrency-mt-unsafe)
  GnuplotCapture(const GnuplotCapture&) = delete;
  GnuplotCapture& operator=(const GnuplotCapture&) = delete;

  [[nodiscard]] std::string File(const std::string& name) const {
    return ReadFile((captured_ / name).string());
  }

 private:
  TempDir dir_;
  fs::path bin_ = fs::path(dir_.str()) / "bin";
  fs::path captured_ = fs::path(dir_.str()) / "captured";
  std::string old_path_;
};

// Writes the PNGs through the capturing wrapper; false (the test skips) without gnuplot.
bool Plot(const JitterReport& r, const TimingTrace& trace, std::unique_ptr<GnuplotCapture>& out) {
  const std::string real = testing::FindOnPath("gnuplot");
  if (real.empty()) return false;
  out = std::make_unique<GnuplotCapture>(real);
  const TempDir dir;
  (void)WriteJitterPlots(r, trace, dir.str());
  return true;
}

// The script's panels: the text of each from the previous `plot` command to its own.
std::vector<std::string> Panels(const std::string& script) {
  std::vector<std::string> panels;
  std::size_t begin = 0;
  for (std::size_t at = script.find("\nplot "); at != std::string::npos;
       at = script.find("\nplot ", at + 1)) {
    const std::size_t end = script.find('\n', at + 1);
    panels.push_back(script.substr(begin, end - begin));
    begin = end;
  }
  return panels;
}

// The rows of a whitespace-separated data file, comments left out.
std::vector<std::vector<std::string>> Rows(const std::string& data) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(data);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> row;
    std::istringstream cells(line);
    for (std::string cell; cells >> std::ws && !cells.eof();) {
      if (cells.peek() == '"') {
        cells.ignore(1);
        std::getline(cells, cell, '"');
      } else {
        cells >> cell;
      }
      row.push_back(cell);
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(JitterPictures, GnuplotHistogramDrawsTheDeadlineInsideItsRange) {
  const TracedRun run = MakeTracedRun();
  std::unique_ptr<GnuplotCapture> gp;
  if (!Plot(AnalyzeJitter(run.trace, &run.kernel), run.trace, gp)) GTEST_SKIP() << "no gnuplot";
  const std::string script = gp->File("histogram.gp");
  EXPECT_NE(script.find("set arrow from 50.000000, graph 0 to 50.000000, graph 1"),
            std::string::npos) << script;
  EXPECT_NE(script.find("title 'deadline 50 us'"), std::string::npos) << script;
  const std::size_t range = script.find("set xrange [");
  ASSERT_NE(range, std::string::npos) << "the deadline must be inside the range\n" << script;
  double lo = 0;
  double hi = 0;
  ASSERT_EQ(std::sscanf(script.c_str() + range, "set xrange [%lf:%lf]", &lo, &hi), 2);
  EXPECT_LT(lo, 3.0);
  EXPECT_GT(hi, kDeadlineUs);
}

TEST(JitterPictures, GnuplotTimelineHasTheDeadlineAndTheMissesInTheResponsePanel) {
  const TracedRun run = MakeTracedRun();
  std::unique_ptr<GnuplotCapture> gp;
  if (!Plot(AnalyzeJitter(run.trace, &run.kernel), run.trace, gp)) GTEST_SKIP() << "no gnuplot";
  const std::string script = gp->File("timeline.gp");
  const std::vector<std::string> panels = Panels(script);
  const auto response = std::find_if(panels.begin(), panels.end(), [](const std::string& p) {
    return p.find("set ylabel 'response") != std::string::npos;
  });
  ASSERT_NE(response, panels.end()) << script;
  EXPECT_NE(response->find(", 50 with lines dt 1 lw 2 lc rgb '#000000' title 'deadline 50 us'"),
            std::string::npos)
      << *response;
  EXPECT_NE(response->find("misses.dat' using 1:2 with points"), std::string::npos) << *response;
  const std::vector<std::vector<std::string>> misses = Rows(gp->File("misses.dat"));
  ASSERT_EQ(misses.size(), 2u);
  EXPECT_NEAR(std::stod(misses[0][0]), 0.050, 1e-9);
  EXPECT_NEAR(std::stod(misses[0][1]), 63.1, 1e-9);  // response, not compute (60)
  EXPECT_NEAR(std::stod(misses[1][0]), 0.150, 1e-9);
  EXPECT_NEAR(std::stod(misses[1][1]), 52.1, 1e-9);  // above the deadline, compute (49) below
}

TEST(JitterPictures, GnuplotTimelineAt20kHzPlotsABoundedNumberOfMissMarkers) {
  const TimingTrace trace = Infeasible20kHz();
  std::unique_ptr<GnuplotCapture> gp;
  if (!Plot(AnalyzeJitter(trace, nullptr), trace, gp)) GTEST_SKIP() << "no gnuplot";
  const std::string script = gp->File("timeline.gp");
  // Point markers only from the misses file, and that holds few rows.
  for (std::size_t at = script.find("with points"); at != std::string::npos;
       at = script.find("with points", at + 1)) {
    const std::size_t comma = script.rfind(", ", at);
    const std::size_t begin = comma == std::string::npos ? 0 : comma;
    EXPECT_NE(script.substr(begin, at - begin).find("misses.dat"), std::string::npos)
        << script.substr(begin, at - begin + 12);
  }
  EXPECT_LE(Rows(gp->File("misses.dat")).size(), kMarkerBound);
  // The strip: per time bin, its cycles and missed cycles; every miss counted once.
  const std::vector<std::vector<std::string>> strip = Rows(gp->File("strip.dat"));
  ASSERT_FALSE(strip.empty()) << script;
  EXPECT_LE(strip.size(), 1000u);
  double missed = 0;
  double cycles = 0;
  for (const std::vector<std::string>& row : strip) {
    ASSERT_EQ(row.size(), 4u);  // t_from t_to cycles missed
    cycles += std::stod(row[2]);
    missed += std::stod(row[3]);
    if (std::stod(row[1]) <= 1.0) {
      EXPECT_EQ(row[3], "0") << "a miss before 1 s, bin from " << row[0];
    }
  }
  EXPECT_EQ(missed, 20'000.0);
  EXPECT_EQ(cycles, static_cast<double>(trace.cycles.size()));
  EXPECT_NE(script.find("strip.dat'"), std::string::npos) << script;
}

TEST(JitterPictures, GnuplotCausesNamesTheTopFiveCulpritsWithTheirClass) {
  const TracedRun run = ManyCulprits();
  std::unique_ptr<GnuplotCapture> gp;
  if (!Plot(AnalyzeJitter(run.trace, &run.kernel), run.trace, gp)) GTEST_SKIP() << "no gnuplot";
  const std::vector<std::vector<std::string>> rows = Rows(gp->File("causes.dat"));
  const std::vector<std::vector<std::string>> want = {
      {"irq-a", "interrupt", "6", "6"}, {"irq-b", "interrupt", "5", "5"},
      {"irq-c", "interrupt", "4", "4"}, {"irq-d", "interrupt", "3", "3"},
      {"irq-e", "interrupt", "2", "2"}, {"1 other culprit", "", "1", "1"}};
  EXPECT_EQ(rows, want) << gp->File("causes.dat");
}

}  // namespace
}  // namespace hiltwin::analysis
