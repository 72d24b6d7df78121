// Telemetry out of a RunSession and commands into it (runtime/telemetry.h): the mailbox and
// the command queue on their own, then whole sessions on the virtual clock with a recording
// sink: the record's values are the task's and the monitor's, the final record closes the run,
// commands from a sink reach the lifecycle in order, and the loop still allocates nothing.
#include "hiltwin/runtime/telemetry.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fakes/loop_allocations.h"
#include "hiltwin/lockfree/command_queue.h"
#include "hiltwin/lockfree/latest_value.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::runtime {
namespace {

using lifecycle::State;
using lockfree::CommandQueue;
using lockfree::LatestValue;
using lifecycle::StopReason;

// ---------------------------------------------------------------------------- the mailbox

struct Words {
  std::array<std::uint64_t, 8> word{};
};

TEST(LatestValue, TheReaderGetsNothingNewUntilTheWriterPublishesThenTheNewestValue) {
  LatestValue<Words> box;
  EXPECT_FALSE(box.Update());
  EXPECT_EQ(box.Front().word[0], 0U);
  box.Back().word[0] = 1;
  box.Publish();
  box.Back().word[0] = 2;
  box.Publish();  // overwrites the unread 1: only the newest counts
  EXPECT_TRUE(box.Update());
  EXPECT_EQ(box.Front().word[0], 2U);
  EXPECT_FALSE(box.Update());
  EXPECT_EQ(box.Front().word[0], 2U);  // kept until something newer arrives
  EXPECT_EQ(box.published(), 2U);
}

TEST(LatestValue, AConcurrentReaderNeverSeesATornOrOlderValue) {
  LatestValue<Words> box;
  constexpr std::uint64_t kValues = 200'000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t v = 1; v <= kValues; ++v) {
      box.Back().word.fill(v);
      box.Publish();
    }
    done = true;
  });
  std::uint64_t last = 0, torn = 0, backwards = 0, reads = 0;
  for (;;) {
    const bool finished = done.load();  // read first: a value published before it is seen
    if (!box.Update()) {
      if (finished) break;
      continue;
    }
    ++reads;
    const Words& w = box.Front();
    for (std::uint64_t x : w.word) torn += x != w.word[0] ? 1U : 0U;
    backwards += w.word[0] < last ? 1U : 0U;
    last = w.word[0];
  }
  writer.join();
  EXPECT_EQ(torn, 0U);
  EXPECT_EQ(backwards, 0U);
  EXPECT_GT(reads, 0U);
  EXPECT_EQ(last, kValues);  // the newest value always arrives
}

// ----------------------------------------------------------------------- the command queue

TEST(CommandQueue, KeepsTheOrderAndRefusesWhenFull) {
  CommandQueue<SessionCommand, 4> queue;
  EXPECT_FALSE(queue.MaybeNonEmpty());
  EXPECT_TRUE(queue.TryPush(SessionCommand::kResume));
  EXPECT_TRUE(queue.TryPush(SessionCommand::kPause));
  EXPECT_TRUE(queue.TryPush(SessionCommand::kStop));
  EXPECT_TRUE(queue.TryPush(SessionCommand::kPause));
  EXPECT_FALSE(queue.TryPush(SessionCommand::kStop));  // full: refused, not overwritten
  EXPECT_TRUE(queue.MaybeNonEmpty());
  SessionCommand c{};
  std::vector<SessionCommand> got;
  while (queue.TryPop(c)) got.push_back(c);
  EXPECT_EQ(got, (std::vector{SessionCommand::kResume, SessionCommand::kPause,
                              SessionCommand::kStop, SessionCommand::kPause}));
  EXPECT_FALSE(queue.MaybeNonEmpty());
  EXPECT_TRUE(queue.TryPush(SessionCommand::kStop));  // the slots come back
}

TEST(CommandQueue, TwoProducersAndOneConsumerLoseNothingAndKeepEachProducersOrder) {
  CommandQueue<std::uint32_t, 16> queue;
  constexpr std::uint32_t kEach = 20'000;
  const auto produce = [&queue](std::uint32_t tag) {
    for (std::uint32_t i = 0; i < kEach; ++i) {
      while (!queue.TryPush(tag | i)) std::this_thread::yield();
    }
  };
  std::thread a(produce, 0x0000'0000U), b(produce, 0x8000'0000U);
  std::array<std::uint32_t, 2> next{};
  std::uint64_t received = 0, out_of_order = 0;
  while (received < 2 * kEach) {
    std::uint32_t v = 0;
    if (!queue.TryPop(v)) continue;
    const std::size_t producer = v >> 31;
    out_of_order += (v & 0x7fff'ffffU) != next[producer] ? 1U : 0U;
    next[producer] = (v & 0x7fff'ffffU) + 1;
    ++received;
  }
  a.join();
  b.join();
  EXPECT_EQ(out_of_order, 0U);
  EXPECT_EQ(next[0], kEach);
  EXPECT_EQ(next[1], kEach);
}

// ------------------------------------------------------------------ sessions with telemetry

/// A task that moves along x by a millimetre per step and turns a little.
class MovingTask final : public RunTask {
 public:
  io::ExchangeStatus Exchange(bool) noexcept override { return {.board_answered = true}; }
  StepStatus Step(const scheduler::CycleContext&) noexcept override {
    ++steps;
    return StepStatus::Ok();
  }
  std::vector<std::string> LogColumns() const override { return {"steps"}; }
  double LogTimeS() const noexcept override { return static_cast<double>(steps) * 1e-3; }
  void FillLogRow(std::span<double> values) const noexcept override {
    values[0] = static_cast<double>(steps);
  }
  TelemetryShape TelemetryShapeOf() const override { return {"twin", true, {"left", "right"}}; }
  void FillTelemetry(TaskTelemetry& out) const noexcept override {
    out.has_pose = true;
    out.x_m = static_cast<double>(steps) * 1e-3;
    out.y_m = -1.0;
    out.theta_rad = static_cast<double>(steps) * 1e-4;
    out.joint_count = 2;
    out.joint_position_m = {0.5, 0.25, 0.0, 0.0};
    out.joint_position_rad = {10.0, 5.0, 0.0, 0.0};
  }
  std::uint64_t steps = 0;
};

/// Records what the session publishes; sends a scripted command on each poll.
class RecordingSink final : public TelemetrySink {
 public:
  void Open(const TelemetryShape& shape, const std::string& ns) override {
    if (fail_open) throw std::runtime_error("port 8080 is in use");
    opened_shape = shape;
    opened_ns = ns;
  }
  void Publish(const TelemetryRecord& record) noexcept override {
    std::lock_guard lock(mutex);
    records.push_back(record);
  }
  void PollCommands(const CommandPort& port) noexcept override {
    std::lock_guard lock(mutex);
    ++polls;
    // One command per poll, and only once the previous one shows in the published state.
    if (script.empty() || records.empty()) return;
    if (!script.front().when_state || records.back().state == *script.front().when_state) {
      std::string why;
      answers.push_back(port(script.front().command, why) ? "taken" : why);
      script.erase(script.begin());
    }
  }
  std::string Describe() const override { return "recording"; }

  struct Step {
    RemoteCommand command;
    std::optional<State> when_state;
  };
  std::vector<Step> script;
  bool fail_open = false;
  TelemetryShape opened_shape;
  std::string opened_ns;
  std::mutex mutex;
  std::vector<TelemetryRecord> records;
  std::vector<std::string> answers;
  int polls = 0;
};

SessionConfig VirtualConfig(std::uint64_t cycles, std::shared_ptr<RecordingSink> sink) {
  SessionConfig config;
  config.clock = ClockKind::kVirtual;
  config.rate_hz = 1000.0;
  config.executive.period_ns = 1'000'000;
  config.executive.max_cycles = cycles;
  config.qos.rules = {qos::MakeMissRatioRule(1.0), qos::MakeMkRule(1, 2)};
  config.qos.planned_cycles = cycles;
  config.telemetry.ns = "bench1/twin";
  config.telemetry.rate_hz = 200.0;
  config.telemetry.sinks = {std::move(sink)};
  return config;
}

TEST(RunSessionTelemetry, TheFinalRecordHoldsTheTasksLastValuesAndTheRunsVerdict) {
  MovingTask task;
  auto sink = std::make_shared<RecordingSink>();
  SessionConfig config = VirtualConfig(1000, sink);
  // 2 wake-ups in 100 are 50 us late: 20 of the last 1000, so the p99 is one of them.
  config.virtual_costs.wake_latency_ns.assign(100, 1'000);
  config.virtual_costs.wake_latency_ns[10] = config.virtual_costs.wake_latency_ns[60] = 50'000;
  RunSession session(std::move(config), task);
  EXPECT_EQ(sink->opened_ns, "bench1/twin");
  EXPECT_EQ(sink->opened_shape.joint_names, (std::vector<std::string>{"left", "right"}));
  const RunReport report = session.Run();
  ASSERT_FALSE(sink->records.empty());
  const TelemetryRecord& last = sink->records.back();
  EXPECT_TRUE(last.final);
  EXPECT_EQ(std::count_if(sink->records.begin(), sink->records.end(),
                          [](const TelemetryRecord& r) { return r.final; }),
            1);
  EXPECT_EQ(last.ns, "bench1/twin");
  EXPECT_EQ(last.role, "twin");
  EXPECT_EQ(last.state, State::kStopped);
  EXPECT_EQ(last.cycle, report.cycles_run);
  EXPECT_EQ(last.cycles_planned, 1000U);
  EXPECT_DOUBLE_EQ(last.rate_hz, 1000.0);
  EXPECT_DOUBLE_EQ(last.time_s, task.LogTimeS());
  EXPECT_DOUBLE_EQ(last.task.x_m, 1.0);
  EXPECT_DOUBLE_EQ(last.task.y_m, -1.0);
  EXPECT_DOUBLE_EQ(last.task.theta_rad, 0.1);
  EXPECT_EQ(last.joint_names, (std::vector<std::string>{"left", "right"}));
  EXPECT_DOUBLE_EQ(last.task.joint_position_rad[1], 5.0);
  EXPECT_EQ(last.deadline_misses, report.misses.deadline_misses);
  EXPECT_EQ(last.verdict_so_far, report.verdict);
  EXPECT_EQ(last.latency_samples, 1000U);  // the last second at 1 kHz
  EXPECT_DOUBLE_EQ(last.latency_p99_us, 50.0);
  EXPECT_DOUBLE_EQ(last.latency_max_us, 50.0);
  ASSERT_TRUE(last.distance_to_violation.has_value());  // (1,2)-firm: two misses in a row
  EXPECT_EQ(*last.distance_to_violation, 2U);
}

TEST(RunSessionTelemetry, CommandsFromASinkReachTheLifecycleInOrder) {
  MovingTask task;
  auto sink = std::make_shared<RecordingSink>();
  sink->script = {{RemoteCommand::kPause, std::nullopt},
                  {RemoteCommand::kInitialise, State::kPaused},
                  {RemoteCommand::kStart, State::kPaused},
                  {RemoteCommand::kReset, State::kRun},
                  {RemoteCommand::kStop, State::kRun}};
  // Until stopped: the virtual loop runs as fast as it can until the STOP arrives.
  RunSession session(VirtualConfig(4'000'000'000ULL, sink), task);
  const RunReport report = session.Run();
  EXPECT_EQ(report.stop_reason, StopReason::kStopRequested);
  EXPECT_EQ(report.final_state, State::kStopped);
  EXPECT_GT(report.cycles_paused, 0U);
  EXPECT_LT(report.cycles_run, 4'000'000'000ULL);
  ASSERT_EQ(sink->answers.size(), 5U);
  EXPECT_EQ(sink->answers[0], "taken");
  EXPECT_NE(sink->answers[1].find("initialises once"), std::string::npos) << sink->answers[1];
  EXPECT_EQ(sink->answers[2], "taken");
  EXPECT_NE(sink->answers[3].find("stopped task"), std::string::npos) << sink->answers[3];
  EXPECT_EQ(sink->answers[4], "taken");
  EXPECT_TRUE(sink->records.back().final);
  EXPECT_EQ(sink->records.back().state, State::kStopped);
}

TEST(RunSessionTelemetry, TheLoopStillAllocatesNothing) {
  MovingTask task;
  auto sink = std::make_shared<RecordingSink>();
  RunSession session(VirtualConfig(200'000, sink), task);
  test::LoopAllocations allocations;
  session.SetLoopThreadHooks(&allocations);
  const RunReport report = session.Run();
  EXPECT_EQ(report.cycles_run, 200'000U);
  EXPECT_EQ(allocations.count, 0U);
}

TEST(RunSessionTelemetry, ASinkThatCannotOpenFailsTheSessionWithItsReason) {
  MovingTask task;
  auto sink = std::make_shared<RecordingSink>();
  sink->fail_open = true;
  try {
    RunSession session(VirtualConfig(10, sink), task);
    FAIL() << "the session was built";
  } catch (const TelemetryError& e) {
    EXPECT_STREQ(e.what(), "port 8080 is in use");
  }
}

TEST(RunSessionTelemetry, RemoteCommandCodesAreTheSeedFrameworksOnes) {
  EXPECT_EQ(RemoteCommandOf(1), RemoteCommand::kInitialise);
  EXPECT_EQ(RemoteCommandOf(3), RemoteCommand::kStop);
  EXPECT_EQ(RemoteCommandOf(6), RemoteCommand::kQuit);
  EXPECT_FALSE(RemoteCommandOf(0).has_value());
  EXPECT_FALSE(RemoteCommandOf(7).has_value());
  EXPECT_STREQ(ToString(RemoteCommand::kPause), "PAUSE");
}

}  // namespace
}  // namespace hiltwin::runtime
