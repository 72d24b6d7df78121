// The loop while an LTTng session records every hiltwin event: still not one heap allocation
// on the loop thread (the tracepoints write into LTTng's preallocated ring buffer), and every
// event it fired is in the trace. In-process, so the loop's allocations can be counted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fakes/alloc_counter.h"
#include "fakes/loop_allocations.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "hiltwin/trace_capture/lttng_session.h"
#include "hiltwin/traces/trace_readers.h"

namespace hiltwin {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kCycles = 5'000;
constexpr std::uint64_t kHeldEvery = 100;  // a corrupted frame: inputs held, io_error traced

class HeldInputsTask final : public runtime::RunTask {
 public:
  io::ExchangeStatus Exchange(bool) noexcept override {
    const bool held = ++exchanges_ % kHeldEvery == 0;
    return {.code = held ? io::ExchangeStatus::Code::kCorrupted : io::ExchangeStatus::Code::kOk,
            .reason = held ? "a corrupted frame" : "",
            .board_answered = !held};
  }
  runtime::StepStatus Step(const scheduler::CycleContext&) noexcept override { return {}; }
  std::vector<std::string> LogColumns() const override { return {}; }
  double LogTimeS() const noexcept override { return 0.0; }
  void FillLogRow(std::span<double>) const noexcept override {}

 private:
  std::uint64_t exchanges_ = 0;
};

using test::LoopAllocations;

TEST(RecordingLoop, AllocatesNothingAndEveryEventIsInTheTrace) {
  const fs::path dir =
      fs::temp_directory_path() / ("hiltwin_recording_" + std::to_string(getpid()));
  fs::remove_all(dir);
  runtime::SessionConfig config;
  config.clock = runtime::ClockKind::kVirtual;
  config.rate_hz = 4000.0;
  config.executive.period_ns = 250'000;
  config.executive.max_cycles = kCycles;
  config.qos.rules = {qos::MakeMkRule(3, 4)};
  config.qos.planned_cycles = kCycles;
  config.injector.Add(runtime::ParseOverrunInjection("every=997,extra-us=600"));
  std::optional<trace_capture::LttngSession> recording;
  try {
    // Sized for 100 kHz: a virtual-clock run fires its events far faster than real time.
    recording.emplace(trace_capture::LttngSessionConfig{
        .output_dir = dir.string(), .rate_hz = 100'000.0, .only_pid = static_cast<int>(getpid()),
        .await_registration = true});
  } catch (const trace_capture::CaptureError& e) {
    GTEST_SKIP() << e.what();
  }
  HeldInputsTask task;
  LoopAllocations allocations;
  runtime::RunSession session(config, task);
  session.SetLoopThreadHooks(&allocations);
  const runtime::RunReport report = session.Run();
  const auto figures = recording->Stop();
  EXPECT_EQ(allocations.count, 0U) << "malloc counted: " << test::MallocIsCounted();
  ASSERT_EQ(figures.discarded_events, 0U);

  const analysis::TimingTrace trace = analysis::ReadCtfTrace(dir.string(), getpid());
  EXPECT_EQ(trace.cycles.size(), report.cycles_run);
  EXPECT_TRUE(trace.complete);
  const auto count = [&](analysis::TracedEventKind kind) {
    return std::count_if(trace.events.begin(), trace.events.end(),
                         [kind](const analysis::TracedEvent& e) { return e.kind == kind; });
  };
  EXPECT_EQ(count(analysis::TracedEventKind::kIoError), kCycles / kHeldEvery);
  EXPECT_EQ(count(analysis::TracedEventKind::kOverrunInjected),
            (kCycles - 1) / 997 + 1);  // k=0 too
  EXPECT_EQ(static_cast<std::uint64_t>(count(analysis::TracedEventKind::kDeadlineMiss)),
            report.misses.deadline_misses - report.releases_skipped);
  EXPECT_GE(count(analysis::TracedEventKind::kStateTransition), 3);  // ready, run, stopping...
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hiltwin
