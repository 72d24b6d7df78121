// Every output of the jitter report: JSON keys, the text's key lines, the Perfetto trace
// (parsed back), the PNGs (gnuplot) and the self-contained HTML page.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_fixtures.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;

using testing::MakeTracedRun;
using testing::TracedRun;
using testing::ReadFile;
using testing::TempDir;

bool GnuplotInstalled() { return !testing::FindOnPath("gnuplot").empty(); }

TEST(JitterOutputs, JsonHoldsEveryFigureUnderStableKeys) {
  const TracedRun run = MakeTracedRun();
  const JitterReport r = AnalyzeJitter(run.trace, &run.kernel);
  const nlohmann::json j = nlohmann::json::parse(JitterToJson(r).dump());  // round trip
  for (const char* key :
       {"source", "path", "period_ns", "deadline_ns", "first_release_ns", "cycles", "cycles_judged",
        "releases_skipped", "deadline_misses", "miss_pct", "trace_complete", "discarded_events",
        "kernel_recorded", "kernel_lost_events", "loop", "latency_ns", "period_jitter_ns",
        "compute_ns", "response_ns", "clusters", "worst", "notable", "causes", "warnings"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["source"], "lttng");
  EXPECT_EQ(j["deadline_misses"], 4);  // 1000, 1001 (skipped), 3000, 3001 (skipped)
  EXPECT_EQ(j["latency_ns"]["p999"], r.latency.summary.p999_ns);
  EXPECT_EQ(j["latency_ns"]["bins"].size(), r.latency.bins.size());
  EXPECT_TRUE(j["latency_ns"]["bins"][0].contains("low_ns"));
  EXPECT_EQ(j["clusters"]["windows"][0]["rule"]["kind"], "mk_firm");
  EXPECT_EQ(j["worst"].size(), 10u);
  EXPECT_EQ(j["worst"][0]["k"], 1000);
  EXPECT_EQ(j["worst"][0]["cause"]["class"], "interrupt");
  EXPECT_EQ(j["worst"][0]["cause"]["interrupt"], "eth0");
  for (const char* key : {"class", "duration_ns", "cpu", "thread", "pid", "policy", "priority",
                          "interrupt", "irq", "faults", "address", "evidence"}) {
    EXPECT_TRUE(j["notable"][0]["cause"].contains(key)) << key;
  }
  EXPECT_EQ(j["causes"][0]["culprits"][0]["name"].is_string(), true);
  EXPECT_EQ(j["loop"]["tid"], testing::kLoopTid);
}

TEST(JitterOutputs, TextStatesTheKeyFiguresAndNeverHidesDiscardedEvents) {
  const TracedRun run = MakeTracedRun();
  const JitterReport r = AnalyzeJitter(run.trace, &run.kernel);
  const std::string text = FormatJitterText(r);
  for (const char* line :
       {"hiltwin jitter report: synthetic (lttng)", "period 50 us, deadline 50 us",
        "deadline misses: 4", "0 events discarded by the tracer",
        "loop thread tid 1000 on CPU 1 (SCHED_FIFO 80)", "latency ", "period jitter |x|",
        "compute ", "response ", "wake-up latency histogram", "misses: 4 in 2 bursts",
        "(3,4)-firm", "10 worst stalls by response time", "interrupt: eth0 (irq 42) for 40 us",
        "causes of the", "warnings: none"}) {
    EXPECT_NE(text.find(line), std::string::npos) << "missing: " << line << "\n" << text;
  }
  EXPECT_LT(std::count(text.begin(), text.end(), '\n'), 120);  // a few screens
}

TEST(JitterOutputs, TextSaysWhenCausesWereNotRecorded) {
  const TracedRun run = MakeTracedRun();
  const std::string text = FormatJitterText(AnalyzeJitter(run.trace, nullptr));
  EXPECT_NE(text.find("causes were not recorded: run `hiltwin trace --kernel`"), std::string::npos);
  EXPECT_NE(text.find("kernel: not recorded"), std::string::npos);
}

TEST(JitterOutputs, PerfettoTraceParsesWithOneSlicePerCycleAndOneInstantPerMiss) {
  const TracedRun run = MakeTracedRun();
  const JitterReport r = AnalyzeJitter(run.trace, &run.kernel);
  const TempDir dir;
  const std::string path = WritePerfettoTrace(r, run.trace, &run.kernel, dir.str());
  EXPECT_EQ(path, dir.str() + "/perfetto_trace.json");
  const nlohmann::json j = nlohmann::json::parse(ReadFile(path));
  EXPECT_EQ(j["displayTimeUnit"], "ns");
  std::size_t slices = 0;
  std::size_t instants = 0;
  std::size_t names = 0;
  double last_ts = -1.0;
  double first_ts = -1.0;
  for (const nlohmann::json& e : j["traceEvents"]) {
    const std::string ph = e["ph"];
    const bool loop = e["pid"] == testing::kLoopPid;  // else the kernel's tracks
    if (ph == "M") {
      if (loop) ++names;
      continue;
    }
    const double ts = e["ts"];
    EXPECT_GE(ts, last_ts);  // monotonic, the kernel's tracks included
    last_ts = ts;
    if (!loop) continue;
    if (first_ts < 0.0) first_ts = ts;
    if (ph == "X") {
      ++slices;
      EXPECT_EQ(e["name"], "cycle");
      EXPECT_EQ(e["tid"], testing::kLoopTid);
      EXPECT_TRUE(e["args"].contains("k"));
      EXPECT_TRUE(e["args"].contains("latency_ns"));
      EXPECT_TRUE(e["args"].contains("compute_ns"));
      EXPECT_GT(e["dur"].get<double>(), 0.0);
    } else if (ph == "i") {
      ++instants;
      EXPECT_EQ(e["s"], "t");
    }
  }
  EXPECT_EQ(slices, run.trace.cycles.size());
  EXPECT_EQ(instants, r.misses);
  EXPECT_EQ(names, 2u);  // process and thread names
  EXPECT_DOUBLE_EQ(first_ts,
                   static_cast<double>(run.trace.cycles.front().sample.release_ns) / 1e3);
}

TEST(JitterOutputs, PngsAreWrittenByGnuplot) {
  if (!GnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed (Debian: gnuplot-nox)";
  const TracedRun run = MakeTracedRun();
  const TempDir dir;
  for (const KernelTrace* kernel : {&run.kernel, static_cast<const KernelTrace*>(nullptr)}) {
    const JitterReport r = AnalyzeJitter(run.trace, kernel);
    const std::vector<std::string> paths = WriteJitterPlots(r, run.trace, dir.str());
    ASSERT_EQ(paths.size(), 3u);
    EXPECT_EQ(paths[0], dir.str() + "/jitter_latency_histogram.png");
    EXPECT_EQ(paths[1], dir.str() + "/jitter_timeline.png");
    EXPECT_EQ(paths[2], dir.str() + "/jitter_causes.png");
    for (const std::string& p : paths) {
      const std::string bytes = ReadFile(p);
      ASSERT_GT(bytes.size(), 8u) << p;
      EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << p;
    }
  }
}

TEST(JitterOutputs, PlotsIntoAMissingDirectoryFailNamingTheFile) {
  if (!GnuplotInstalled()) GTEST_SKIP() << "gnuplot is not installed (Debian: gnuplot-nox)";
  const TracedRun run = MakeTracedRun();
  const JitterReport r = AnalyzeJitter(run.trace, nullptr);
  try {
    (void)WriteJitterPlots(r, run.trace, "/nonexistent-hiltwin-dir");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-hiltwin-dir/jitter_latency_histogram.png"),
              std::string::npos)
        << e.what();
  }
}

TEST(JitterOutputs, HtmlIsOnePageWithInlineSvgAndNothingFromOutside) {
  const TracedRun run = MakeTracedRun();
  const TempDir dir;
  for (const KernelTrace* kernel : {&run.kernel, static_cast<const KernelTrace*>(nullptr)}) {
    const JitterReport r = AnalyzeJitter(run.trace, kernel);
    const std::string path = WriteJitterHtml(r, run.trace, dir.str());
    EXPECT_EQ(path, dir.str() + "/jitter_report.html");
    const std::string html = ReadFile(path);
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_EQ(html.find("http://"), std::string::npos);
    EXPECT_EQ(html.find("https://"), std::string::npos);
    EXPECT_EQ(html.find("@import"), std::string::npos);
    EXPECT_EQ(html.find("url("), std::string::npos);
    std::size_t svgs = 0;
    for (std::size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 1)) ++svgs;
    EXPECT_EQ(svgs, 3u);
    EXPECT_NE(html.find("hiltwin jitter report: synthetic"), std::string::npos);  // the text
    EXPECT_NE(html.find("</html>"), std::string::npos);
  }
}

}  // namespace
}  // namespace hiltwin::analysis
