// Records the kernel's events of CPU 0 while a SCHED_FIFO thread preempts a SCHED_OTHER one
// there, and checks the recording says so. Needs root and tracefs; skips with the recorder's
// own reason otherwise. Label `integration`, lock `tracefs`.
#include "hiltwin/trace_capture/kernel_recorder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <thread>

#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/traces/kernel_events.h"

namespace {

namespace fs = std::filesystem;
using hiltwin::analysis::KernelEvent;
using hiltwin::analysis::KernelEventKind;
using hiltwin::analysis::KernelTask;
using hiltwin::analysis::KernelTrace;
using hiltwin::kernel_glue::NamedThread;
using hiltwin::trace_capture::KernelRecorder;
using hiltwin::trace_capture::KernelRecorderConfig;

constexpr int kHogPriority = 90;
constexpr int kHogBursts = 5;
constexpr std::int64_t kHogSpinNs = 20'000'000;
constexpr std::int64_t kHogSleepNs = 30'000'000;

std::int64_t MonotonicNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

void SpinFor(std::int64_t duration_ns) {
  const std::int64_t end_ns = MonotonicNs() + duration_ns;
  while (MonotonicNs() < end_ns) {
  }
}

void SleepFor(std::int64_t duration_ns) {
  const timespec duration{.tv_sec = 0, .tv_nsec = static_cast<long>(duration_ns)};
  clock_nanosleep(CLOCK_MONOTONIC, 0, &duration, nullptr);
}

// Waits (bounded) for `flag`; false when it did not come.
bool Await(const std::atomic<bool>& flag, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!flag.load()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

class KernelRecorderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string refused = KernelRecorder::WhyCannotRecord();
    if (!refused.empty()) GTEST_SKIP() << refused;
    online_cpus_ = std::thread::hardware_concurrency();
    dir_ = fs::temp_directory_path() / ("hiltwin_kernel_recorder_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // CPU 0 recorded; the collector elsewhere when there is an elsewhere.
  [[nodiscard]] KernelRecorderConfig Config() const {
    KernelRecorderConfig config;
    config.output_dir = dir_.string();
    config.cpus = {0};
    if (online_cpus_ > 1) config.collector_cpus = {1};
    return config;
  }

  fs::path dir_;
  unsigned online_cpus_ = 1;
};

// The scene on CPU 0: `cap-victim` (SCHED_OTHER) spins all along; `cap-hog` (SCHED_FIFO 90)
// spins 20 ms and sleeps 30 ms, five times, so it preempts the victim at each wake-up. Both
// are still alive when the recorder stops, so their policies can be read.
struct Scene {
  std::atomic<bool> hog_is_fifo{false};
  std::atomic<bool> hog_done{false};
  std::atomic<bool> release{false};
  NamedThread victim;
  NamedThread hog;

  Scene() {
    victim = NamedThread({.name = "cap-victim", .cpus = {0}}, [this] {
      while (!release.load(std::memory_order_relaxed)) {
      }
    });
    hog = NamedThread({.name = "cap-hog", .cpus = {0}}, [this] {
      const sched_param param{.sched_priority = kHogPriority};
      hog_is_fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
      for (int burst = 0; burst < kHogBursts; ++burst) {
        SpinFor(kHogSpinNs);
        SleepFor(kHogSleepNs);
      }
      hog_done = true;
      while (!release.load()) SleepFor(1'000'000);
    });
  }
  ~Scene() { release = true; }  // the threads join after this, as members
};

std::vector<const KernelEvent*> SwitchesInto(const KernelTrace& trace, const std::string& comm) {
  std::vector<const KernelEvent*> found;
  for (const KernelEvent& event : trace.events) {
    if (event.kind == KernelEventKind::kSchedSwitch && event.next_comm == comm) {
      found.push_back(&event);
    }
  }
  return found;
}

const KernelTask* TaskNamed(const KernelTrace& trace, const std::string& comm) {
  for (const KernelTask& task : trace.tasks) {
    if (task.comm == comm) return &task;
  }
  return nullptr;
}

TEST_F(KernelRecorderTest, SeesTheFifoThreadPreemptTheOtherOnCpu0) {
  const std::int64_t before_ns = MonotonicNs();
  KernelRecorder recorder(Config());
  KernelTrace trace;
  {
    Scene scene;
    ASSERT_TRUE(Await(scene.hog_done, std::chrono::seconds(20)));
    ASSERT_TRUE(scene.hog_is_fifo) << "cannot make cap-hog SCHED_FIFO here";
    trace = recorder.Stop();
  }
  const std::int64_t after_ns = MonotonicNs();

  ASSERT_TRUE(fs::exists(dir_ / "kernel_events.csv"));
  EXPECT_EQ(hiltwin::analysis::ReadKernelTrace(dir_.string()), trace);
  EXPECT_EQ(trace.cpus, std::vector<int>{0});
  EXPECT_EQ(trace.lost_events, 0U);

  // The hog is named (and pinned) before it makes itself SCHED_FIFO, so the scheduler may run
  // it once or twice at SCHED_OTHER's prio 120 first (seen once in a quick tier); from its
  // first switch in at its real-time prio on, every switch into it is at that prio.
  auto into_hog = SwitchesInto(trace, "cap-hog");
  const int fifo_prio = 99 - kHogPriority;  // kernel prio of SCHED_FIFO 90
  const auto first_fifo = std::find_if(into_hog.begin(), into_hog.end(), [&](const KernelEvent* e) {
    return e->next_prio == fifo_prio;
  });
  for (auto it = into_hog.begin(); it != first_fifo; ++it) EXPECT_EQ((*it)->next_prio, 120);
  into_hog.erase(into_hog.begin(), first_fifo);
  EXPECT_GE(into_hog.size(), static_cast<std::size_t>(kHogBursts));
  for (const KernelEvent* event : into_hog) {
    EXPECT_EQ(event->cpu, 0);
    EXPECT_EQ(event->next_prio, fifo_prio);
  }
  // The victim never sleeps: every switch away from it is a preemption (prev_state 0).
  int victim_preempted = 0;
  for (const KernelEvent& event : trace.events) {
    if (event.kind != KernelEventKind::kSchedSwitch || event.comm != "cap-victim") continue;
    EXPECT_EQ(event.prev_state, 0) << "at " << event.time_ns << " into " << event.next_comm;
    ++victim_preempted;
  }
  EXPECT_GT(victim_preempted, 0);

  const KernelTask* hog = TaskNamed(trace, "cap-hog");
  ASSERT_NE(hog, nullptr);
  EXPECT_EQ(hog->policy, "SCHED_FIFO");
  EXPECT_EQ(hog->rt_priority, kHogPriority);
  const KernelTask* victim = TaskNamed(trace, "cap-victim");
  ASSERT_NE(victim, nullptr);
  EXPECT_EQ(victim->policy, "SCHED_OTHER");

  EXPECT_TRUE(std::any_of(trace.events.begin(), trace.events.end(), [](const KernelEvent& e) {
    return e.kind == KernelEventKind::kLocalTimerEntry && e.cpu == 0;
  }));
  for (const KernelEvent& event : trace.events) {
    EXPECT_EQ(event.cpu, 0) << hiltwin::analysis::ToString(event.kind) << " at " << event.time_ns;
    EXPECT_GE(event.time_ns, before_ns);  // CLOCK_MONOTONIC, inside the recording
    EXPECT_LE(event.time_ns, after_ns);
  }
  EXPECT_TRUE(std::is_sorted(
      trace.events.begin(), trace.events.end(),
      [](const KernelEvent& a, const KernelEvent& b) { return a.time_ns < b.time_ns; }));
}

// Records CPU 0 while a thread there sleeps 50 us at a time for `duration_ns` (each round a
// wake-up, two switches, a timer interrupt: tens of thousands of events a second).
KernelTrace RecordBusyCpu0(KernelRecorderConfig config, std::int64_t duration_ns) {
  KernelRecorder recorder(config);
  std::atomic<bool> done{false};
  NamedThread sleeper({.name = "cap-sleeper", .cpus = {0}}, [&done, duration_ns] {
    const std::int64_t end_ns = MonotonicNs() + duration_ns;
    while (MonotonicNs() < end_ns) SleepFor(50'000);
    done = true;
  });
  EXPECT_TRUE(Await(done, std::chrono::seconds(30)));
  sleeper.Join();
  const KernelTrace& trace = recorder.Stop();
  EXPECT_EQ(&recorder.Stop(), &trace);  // idempotent: the same recording
  return trace;
}

TEST_F(KernelRecorderTest, TheCollectorDrainsSoMoreThanTheBufferFits) {
  // What the buffer holds of this load is measured, not guessed: once with a collector that
  // only drains at the end (so the buffer overflows), once with the usual 100 ms drains. The
  // buffer is several times what arrives in 100 ms, so a busy machine does not overflow it.
  KernelRecorderConfig config = Config();
  config.buffer_kb_per_cpu = 2048;
  constexpr std::int64_t kBusyNs = 3'000'000'000;
  config.drain_period_ms = 60'000;
  const KernelTrace undrained = RecordBusyCpu0(config, kBusyNs);
  ASSERT_GT(undrained.lost_events, 0U) << "the load did not overflow the buffer: no test";
  config.drain_period_ms = 100;
  const KernelTrace drained = RecordBusyCpu0(config, kBusyNs);
  RecordProperty("undrained_events", std::to_string(undrained.events.size()));
  RecordProperty("drained_events", std::to_string(drained.events.size()));
  EXPECT_EQ(drained.lost_events, 0U);
  EXPECT_GT(static_cast<double>(drained.events.size()),
            1.5 * static_cast<double>(undrained.events.size()))
      << "a buffer's worth is " << undrained.events.size() << " events";
}

}  // namespace
