// The Perfetto export with the kernel recorded: the other threads that ran on the loop's CPUs
// get a track each, interrupts a track per CPU, beside the loop's cycles; nothing from CPUs
// the loop never used, nothing outside the traced cycles.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_fixtures.h"

namespace hiltwin::analysis {
namespace {
// Named too: the tests are compiled in unity batches, where anonymous namespaces merge.
namespace perfetto_kernel_test {

namespace fs = std::filesystem;
using testing::kLoopCpu;
using testing::kLoopKernelPrio;
using testing::kLoopTid;

constexpr int kHogPid = 4242;
constexpr int kHogKernelPrio = 4;  // SCHED_FIFO 95
constexpr int kOtherCpu = 3;
constexpr std::int64_t kHoldNs = 2'000'000;

struct Recorded {
  TimingTrace trace;
  KernelTrace kernel;
};

// 2000 releases at 50 µs. At k=1000 rt-hog holds the loop's CPU for 2 ms from 100 ns after
// the release; at k=1500 it runs again, switched in untraced (only its wake-up is seen), for
// 15 µs up to 5 µs before the release (the loop slept from 26.4 µs before it); eth0
// interrupts the step of k=500. On CPU 3, which the loop never used, a busy thread runs;
// before the first release a thread runs on the loop's CPU.
Recorded HogRun() {
  testing::RunSpec spec;
  spec.releases = 2'000;
  spec.overrides[1000] = {500 + kHoldNs + 500, 20'000};
  Recorded run{testing::MakeTrace(spec), {}};
  std::map<std::uint64_t, testing::SpecialCycle> special;
  special[1000] = [](testing::KernelScript& k, const scheduler::TimingSample& s) {
    const std::int64_t r = s.release_ns;
    k.Switch(r + 100, kLoopCpu, 0, "swapper/1", 120, 0, kHogPid, "rt-hog", kHogKernelPrio);
    k.LoopWakeup(r + 500);
    k.Switch(r + 500 + kHoldNs, kLoopCpu, kHogPid, "rt-hog", kHogKernelPrio, 1, kLoopTid,
             "hiltwin-loop", kLoopKernelPrio);
    k.LoopOutToIdle(s.end_ns + 500);
  };
  special[1500] = [](testing::KernelScript& k, const scheduler::TimingSample& s) {
    k.Wakeup(s.release_ns - 20'000, kHogPid, "rt-hog", kHogKernelPrio, kLoopCpu);
    k.Switch(s.release_ns - 5'000, kLoopCpu, kHogPid, "rt-hog", kHogKernelPrio, 1, 0,
             "swapper/1", 120);
    testing::NormalCycle(k, s);
  };
  special[500] = [](testing::KernelScript& k, const scheduler::TimingSample& s) {
    testing::NormalCycle(k, s);
    k.Irq(s.start_ns + 1'000, s.start_ns + 6'000, kLoopCpu, 42, "eth0");
  };
  testing::KernelScript script;
  const std::int64_t t0 = run.trace.cycles.front().sample.release_ns;
  script.Switch(t0 - 900'000, kLoopCpu, 0, "swapper/1", 120, 0, 777, "early", 120);
  script.Switch(t0 - 800'000, kLoopCpu, 777, "early", 120, 1, 0, "swapper/1", 120);
  for (std::int64_t t = t0; t < t0 + 90'000'000; t += 1'000'000) {
    script.Switch(t, kOtherCpu, 0, "swapper/3", 120, 0, 555, "busy", 120);
    script.Switch(t + 500'000, kOtherCpu, 555, "busy", 120, 1, 0, "swapper/3", 120);
  }
  KernelTrace extra = script.Finish();
  run.kernel = testing::MakeKernel(run.trace, special);
  run.kernel.events.insert(run.kernel.events.end(), extra.events.begin(), extra.events.end());
  std::stable_sort(
      run.kernel.events.begin(), run.kernel.events.end(),
      [](const KernelEvent& a, const KernelEvent& b) { return a.time_ns < b.time_ns; });
  run.kernel.cpus = {kLoopCpu, kOtherCpu};
  run.kernel.tasks = {{kHogPid, "rt-hog", "SCHED_FIFO", 95}};
  return run;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "hiltwin-perfetto-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] std::string str() const { return path_.string(); }

 private:
  fs::path path_;
};

nlohmann::json WriteAndParse(const Recorded& run, const KernelTrace* kernel) {
  const JitterReport r = AnalyzeJitter(run.trace, kernel);
  const TempDir dir;
  const std::string path = WritePerfettoTrace(r, run.trace, kernel, dir.str());
  std::ifstream in(path, std::ios::binary);
  return nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
}

// Track names by (pid, tid) from the thread_name metadata.
std::map<std::pair<int, int>, std::string> ThreadNames(const nlohmann::json& j) {
  std::map<std::pair<int, int>, std::string> names;
  for (const nlohmann::json& e : j["traceEvents"]) {
    if (e["ph"] == "M" && e["name"] == "thread_name") {
      names[{e["pid"].get<int>(), e["tid"].get<int>()}] = e["args"]["name"];
    }
  }
  return names;
}

std::pair<int, int> TrackNamed(const nlohmann::json& j, const std::string& name) {
  for (const auto& [ids, n] : ThreadNames(j)) {
    if (n == name) return ids;
  }
  return {-1, -1};
}

std::vector<nlohmann::json> SlicesOn(const nlohmann::json& j, std::pair<int, int> track) {
  std::vector<nlohmann::json> out;
  for (const nlohmann::json& e : j["traceEvents"]) {
    if (e["ph"] == "X" && e["pid"] == track.first && e["tid"] == track.second) out.push_back(e);
  }
  return out;
}

double Us(std::int64_t ns) { return static_cast<double>(ns) / 1e3; }

// Cycle k (the trace holds no cycle for a skipped release, so k is not the index).
const scheduler::TimingSample& CycleK(const TimingTrace& trace, std::uint64_t k) {
  for (const TracedCycle& c : trace.cycles) {
    if (c.sample.cycle == k) return c.sample;
  }
  throw std::runtime_error("no cycle " + std::to_string(k));
}

TEST(PerfettoKernel, TheHogGetsATrackNamedAfterItWithItsRunsOnTheLoopsCpu) {
  const Recorded run = HogRun();
  const nlohmann::json j = WriteAndParse(run, &run.kernel);
  const auto hog = TrackNamed(j, "rt-hog (pid 4242, SCHED_FIFO 95)");
  ASSERT_NE(hog.second, -1) << "no track for rt-hog";
  EXPECT_EQ(hog.second, kHogPid);
  EXPECT_NE(hog.first, testing::kLoopPid);  // beside the loop's process, not inside it
  const std::vector<nlohmann::json> slices = SlicesOn(j, hog);
  ASSERT_EQ(slices.size(), 2u);
  const std::int64_t r1000 = CycleK(run.trace, 1000).release_ns;
  EXPECT_NEAR(slices[0]["ts"].get<double>(), Us(r1000 + 100), 1e-3);
  EXPECT_NEAR(slices[0]["dur"].get<double>(), Us(400 + kHoldNs), 1e-3);
  EXPECT_EQ(slices[0]["name"], "rt-hog on CPU 1");
  EXPECT_EQ(slices[0]["args"]["cpu"], kLoopCpu);
  // The second run's switch in was not traced: rebuilt from the wake-up, as the causes are.
  const std::int64_t r1500 = CycleK(run.trace, 1500).release_ns;
  EXPECT_NEAR(slices[1]["ts"].get<double>(), Us(r1500 - 20'000), 1e-3);
  EXPECT_NEAR(slices[1]["dur"].get<double>(), Us(15'000), 1e-3);
}

TEST(PerfettoKernel, InterruptsAreSlicesOnTheirCpusTrack) {
  const Recorded run = HogRun();
  const nlohmann::json j = WriteAndParse(run, &run.kernel);
  const auto irqs = TrackNamed(j, "interrupts on CPU 1");
  ASSERT_NE(irqs.second, -1);
  std::size_t eth0 = 0;
  std::size_t timers = 0;
  for (const nlohmann::json& e : SlicesOn(j, irqs)) {
    if (e["name"] == "eth0 (irq 42)") {
      ++eth0;
      const std::int64_t start = CycleK(run.trace, 500).start_ns;
      EXPECT_NEAR(e["ts"].get<double>(), Us(start + 1'000), 1e-3);
      EXPECT_NEAR(e["dur"].get<double>(), 5.0, 1e-3);
    } else if (e["name"] == "local_timer") {
      ++timers;
    }
  }
  EXPECT_EQ(eth0, 1u);
  EXPECT_EQ(timers, run.trace.cycles.size() - 1);  // every cycle's but k=1000's
}

TEST(PerfettoKernel, OnlyTheLoopsCpusAndOnlyWhileTheLoopRan) {
  const Recorded run = HogRun();
  const nlohmann::json j = WriteAndParse(run, &run.kernel);
  for (const auto& [ids, name] : ThreadNames(j)) {
    EXPECT_EQ(name.find("busy"), std::string::npos) << "CPU 3 was not the loop's";
    EXPECT_EQ(name.find("early"), std::string::npos) << "ran before the first release";
    EXPECT_EQ(name.find("swapper"), std::string::npos) << "the idle task is no thread";
  }
  EXPECT_EQ(TrackNamed(j, "interrupts on CPU 3").second, -1);
  const auto loop = TrackNamed(j, "loop (tid 1000)");
  EXPECT_EQ(loop.first, testing::kLoopPid);
  EXPECT_EQ(SlicesOn(j, loop).size(), run.trace.cycles.size());
}

TEST(PerfettoKernel, WithoutTheKernelOnlyTheLoop) {
  const Recorded run = HogRun();
  const nlohmann::json j = WriteAndParse(run, nullptr);
  EXPECT_EQ(ThreadNames(j).size(), 1u);
  for (const nlohmann::json& e : j["traceEvents"]) EXPECT_EQ(e["pid"], testing::kLoopPid);
}

}  // namespace perfetto_kernel_test
}  // namespace
}  // namespace hiltwin::analysis
