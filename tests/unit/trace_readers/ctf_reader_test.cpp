// ReadCtfTrace on real LTTng traces: a session daemon records the tracing suite's emitter,
// whose every event is known (tests/unit/tracing/trace_emitter_main.cpp), and the reader's
// TimingTrace must hold exactly that. Then the traces it must refuse: a stream file cut in
// half, a trace without hiltwin events. Label `integration`, resource lock `lttng`.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <time.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fakes/lttng_fixture.h"
#include "fakes/test_paths.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/traces/trace_readers.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr std::uint64_t kCount = 500;

std::int64_t MonotonicNowNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

std::vector<std::string> Emitter(std::uint64_t count) {
  return {HILTWIN_TRACE_EMITTER, std::to_string(count)};
}

std::vector<std::string> OddEmitter(const std::string& which) {
  return {HILTWIN_ODD_TRACE_EMITTER, which};
}

std::vector<TracedEvent> EventsOf(const TimingTrace& trace, TracedEventKind kind) {
  std::vector<TracedEvent> events;
  std::copy_if(trace.events.begin(), trace.events.end(), std::back_inserter(events),
               [kind](const TracedEvent& event) { return event.kind == kind; });
  return events;
}

class CtfReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!lttng_.EnsureDaemon()) {
      GTEST_SKIP() << "cannot start lttng-sessiond here; log:\n" << lttng_.CommandLog();
    }
  }

  /// Records `commands` into a fresh folder under the fixture's home; that folder.
  std::string Record(const std::vector<std::vector<std::string>>& commands,
                     const test::LttngFixture::SessionOptions& options = {}) {
    std::string dir = (lttng_.home() / ("trace" + std::to_string(++traces_))).string();
    recording_ = lttng_.Record(dir, commands, options);
    EXPECT_TRUE(recording_.ok) << lttng_.CommandLog();
    return dir;
  }

  static std::string ErrorOf(const std::string& dir) {
    try {
      static_cast<void>(ReadCtfTrace(dir));
    } catch (const TraceReadError& e) {
      return e.what();
    }
    return "";
  }

  test::LttngFixture lttng_{"ctf_reader"};
  test::LttngFixture::Recording recording_;
  int traces_ = 0;
};

TEST_F(CtfReaderTest, ReadsTheEmittersKnownAnswers) {
  const std::int64_t before_ns = MonotonicNowNs();
  const std::string dir = Record({Emitter(kCount)});
  const std::int64_t after_ns = MonotonicNowNs();
  ASSERT_EQ(recording_.pids.size(), 1U);
  const TimingTrace trace = ReadCtfTrace(dir);
  EXPECT_EQ(trace.source, TraceSource::kLttng);
  EXPECT_EQ(trace.path, dir);
  EXPECT_EQ(trace.period_ns, 1000);
  EXPECT_EQ(trace.deadline_ns, 1000);
  EXPECT_EQ(trace.planned_cycles, kCount);
  EXPECT_EQ(trace.rules, std::vector<qos::RuleSpec>{qos::MakeMkRule(3, 4)});
  ASSERT_TRUE(trace.loop.has_value());
  EXPECT_GT(trace.loop->tid, 0);
  EXPECT_EQ(trace.loop->tid, recording_.pids[0]);  // the emitter has one thread
  EXPECT_EQ(trace.loop->cpu, 0);
  EXPECT_EQ(trace.loop->policy, 1);
  EXPECT_EQ(trace.loop->priority, 80);
  EXPECT_EQ(trace.pid, recording_.pids[0]);
  EXPECT_EQ(trace.other_processes, 0U);
  EXPECT_EQ(trace.other_runs, 0U);
  EXPECT_TRUE(trace.complete);
  EXPECT_EQ(trace.discarded_events, 0U);
  EXPECT_EQ(trace.discarded_packets, 0U);

  ASSERT_EQ(trace.cycles.size(), kCount);
  std::uint64_t missed = 0;
  for (std::uint64_t k = 0; k < kCount; ++k) {
    ASSERT_EQ(trace.cycles[k].sample.cycle, k);
    missed += trace.cycles[k].sample.missed ? 1U : 0U;
  }
  EXPECT_EQ(missed, kCount / 10);
  const TracedCycle& c42 = trace.cycles[42];
  EXPECT_EQ(c42.sample.release_ns, 42'000);
  EXPECT_EQ(c42.sample.wake_ns, 42'010);
  EXPECT_EQ(c42.sample.start_ns, 42'020);
  EXPECT_EQ(c42.sample.end_ns, 42'030);  // + 42 % 7 = 0
  EXPECT_EQ(c42.sample.io_ns, 5);
  EXPECT_EQ(c42.sample.releases_skipped, 1U);  // 42 % 3 == 0
  EXPECT_FALSE(c42.sample.missed);
  EXPECT_TRUE(c42.judged);
  EXPECT_EQ(trace.cycles[43].sample.end_ns, 43'031);
  EXPECT_EQ(trace.cycles[43].sample.releases_skipped, 0U);
  EXPECT_TRUE(trace.cycles[40].sample.missed);

  const auto misses = EventsOf(trace, TracedEventKind::kDeadlineMiss);
  ASSERT_EQ(misses.size(), kCount / 10);
  EXPECT_EQ(misses[4].k, 40U);
  EXPECT_EQ(misses[4].a, std::int64_t{40 % 7 + 30 - 1000});
  const auto violations = EventsOf(trace, TracedEventKind::kQosViolation);
  ASSERT_EQ(violations.size(), kCount / 10);
  EXPECT_EQ(violations[4].k, 40U);
  EXPECT_EQ(violations[4].a, 0);  // rule 0
  EXPECT_EQ(violations[4].b, 5);  // violations so far
  const auto io_errors = EventsOf(trace, TracedEventKind::kIoError);
  ASSERT_EQ(io_errors.size(), kCount / 50);
  for (std::size_t i = 0; i < io_errors.size(); ++i) {
    EXPECT_EQ(io_errors[i].k, 50 * i);
    EXPECT_EQ(io_errors[i].a, static_cast<std::int64_t>(i % 4));
  }
  const auto transitions = EventsOf(trace, TracedEventKind::kStateTransition);
  ASSERT_EQ(transitions.size(), 1U);
  EXPECT_EQ(transitions[0].k, 0U);
  EXPECT_EQ(transitions[0].a, 2);
  EXPECT_EQ(transitions[0].b, 3);
  EXPECT_EQ(transitions[0].c, 1);
  EXPECT_TRUE(EventsOf(trace, TracedEventKind::kOverrunInjected).empty());

  // Event times are CLOCK_MONOTONIC (as the kernel's events), in recording order.
  for (std::size_t i = 0; i < trace.events.size(); ++i) {
    EXPECT_GE(trace.events[i].time_ns, before_ns) << "event " << i;
    EXPECT_LE(trace.events[i].time_ns, after_ns) << "event " << i;
    if (i > 0) {
      EXPECT_GE(trace.events[i].time_ns, trace.events[i - 1].time_ns);
    }
  }
}

TEST_F(CtfReaderTest, KeepsTheFirstOfTwoProcesses) {
  const std::string dir = Record({Emitter(300), Emitter(200)});
  ASSERT_EQ(recording_.pids.size(), 2U);
  const TimingTrace trace = ReadCtfTrace(dir);
  EXPECT_EQ(trace.pid, recording_.pids[0]);
  // At least the second emitter; hiltwin processes of other suites running meanwhile too.
  EXPECT_GE(trace.other_processes, 1U);
  EXPECT_EQ(trace.planned_cycles, 300U);
  EXPECT_EQ(trace.cycles.size(), 300U);
  EXPECT_EQ(EventsOf(trace, TracedEventKind::kDeadlineMiss).size(), 30U);
  EXPECT_TRUE(trace.complete);
}

TEST_F(CtfReaderTest, AGivenProcessIsTheOneKept) {
  const std::string dir = Record({Emitter(300), Emitter(200)});
  ASSERT_EQ(recording_.pids.size(), 2U);
  const TimingTrace trace = ReadCtfTrace(dir, recording_.pids[1]);
  EXPECT_EQ(trace.pid, recording_.pids[1]);
  EXPECT_EQ(trace.cycles.size(), 200U);
  EXPECT_EQ(trace.planned_cycles, 200U);
}

TEST_F(CtfReaderTest, WithoutTheVpidContextTheTraceIsOneProcess) {
  const std::string dir = Record({Emitter(100)}, {.vpid = false});
  const TimingTrace trace = ReadCtfTrace(dir);
  EXPECT_EQ(trace.pid, 0);
  EXPECT_EQ(trace.other_processes, 0U);
  EXPECT_EQ(trace.cycles.size(), 100U);
  EXPECT_TRUE(trace.complete);
}

TEST_F(CtfReaderTest, CountsTheEventsTheTracerDropped) {
  // Two 4 KiB sub-buffers cannot hold what the emitter writes at full speed: LTTng drops
  // events and says how many in its packet contexts. Every emitted event is then either read
  // or counted as dropped.
  constexpr std::uint64_t kMany = 200'000;
  const std::string dir = Record({Emitter(kMany)}, {.subbuf_bytes = 4096, .subbuffers = 2});
  const TimingTrace trace = ReadCtfTrace(dir);
  if (trace.discarded_events == 0) GTEST_SKIP() << "the consumer kept up: nothing dropped";
  const std::uint64_t emitted = 3 + kMany + 2 * (kMany / 10) + kMany / 50 + 1;
  const std::uint64_t read = (trace.loop ? 1U : 0U) + trace.rules.size() + trace.cycles.size() +
                             trace.events.size() + (trace.complete ? 1U : 0U);
  EXPECT_EQ(read + trace.discarded_events, emitted);
  EXPECT_LT(trace.cycles.size(), kMany);
  for (std::size_t i = 1; i < trace.cycles.size(); ++i) {
    ASSERT_GT(trace.cycles[i].sample.cycle, trace.cycles[i - 1].sample.cycle);
  }
}

/// The largest CTF stream file below `dir` (not metadata, not an index); empty when none.
fs::path LargestStreamFile(const fs::path& dir) {
  fs::path largest;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const fs::path& path = entry.path();
    if (!entry.is_regular_file() || path.filename() == "metadata" ||
        path.parent_path().filename() == "index") {
      continue;
    }
    if (largest.empty() || entry.file_size() > fs::file_size(largest)) largest = path;
  }
  return largest;
}

TEST_F(CtfReaderTest, AStreamFileCutInHalfIsAnErrorNamingTheFolder) {
  const std::string dir = Record({Emitter(kCount)});
  const fs::path cut = lttng_.home() / "cut";
  fs::copy(dir, cut, fs::copy_options::recursive);
  const fs::path largest = LargestStreamFile(cut);
  ASSERT_FALSE(largest.empty()) << "no stream file in " << dir;
  fs::resize_file(largest, fs::file_size(largest) / 2);
  const std::string message = ErrorOf(cut.string());
  EXPECT_THAT(message, HasSubstr("cannot read the LTTng trace in " + cut.string()));
  EXPECT_THAT(message, HasSubstr(largest.filename().string()));  // babeltrace2's cause

  // Without LTTng's packet index, source.ctf.fs finds the cut by reading the packets.
  fs::remove_all(largest.parent_path() / "index");
  EXPECT_THAT(ErrorOf(cut.string()), HasSubstr("cannot read the LTTng trace in " + cut.string()));
}

TEST_F(CtfReaderTest, ADamagedStreamIsAnErrorNotACrash) {
  // Garbage where events were: the decoder meets an unknown event id (libbabeltrace2 stops
  // the graph) or impossible field values (the reader refuses them); either way a
  // TraceReadError naming the folder.
  const std::string dir = Record({Emitter(kCount)});
  const fs::path damaged = lttng_.home() / "damaged";
  fs::copy(dir, damaged, fs::copy_options::recursive);
  const fs::path largest = LargestStreamFile(damaged);
  ASSERT_FALSE(largest.empty()) << "no stream file in " << dir;
  {
    std::fstream stream(largest, std::ios::in | std::ios::out | std::ios::binary);
    stream.seekp(1000);
    const std::string garbage(64, '\xff');
    stream.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  EXPECT_THAT(ErrorOf(damaged.string()), HasSubstr(damaged.string()));
}

TEST_F(CtfReaderTest, ATraceWithoutHiltwinEventsSaysSo) {
  // The emitter runs, so the session has streams and metadata, but no event is enabled.
  const std::string dir = Record({Emitter(5)}, {.events = "hiltwin_nothing:*"});
  EXPECT_EQ(ErrorOf(dir), dir +
                              ": the LTTng trace holds no hiltwin:cycle event; was `hiltwin:*` "
                              "enabled (lttng enable-event --userspace 'hiltwin:*') while the run "
                              "was going?");
}

TEST_F(CtfReaderTest, ATraceOfOnlyTheLoopStartHasNoCycles) {
  const std::string dir = Record({Emitter(5)}, {.events = "hiltwin:loop_start"});
  EXPECT_THAT(ErrorOf(dir), HasSubstr("holds no hiltwin:cycle event of process " +
                                      std::to_string(recording_.pids[0])));
}

TEST_F(CtfReaderTest, UnknownCodesAreRefusedWithTheEventsPlace) {
  // The odd emitter's events 1-3 are loop_start and cycles 0, 1; the odd one is event 4.
  const std::string io = Record({OddEmitter("io_error_kind")});
  const std::string place = ": event #4 in time order (hiltwin:io_error, vpid " +
                            std::to_string(recording_.pids.at(0)) + "): ";
  EXPECT_EQ(ErrorOf(io), io + place +
                             "unknown kind code 7 (known: 0 to 3); was it recorded by a newer "
                             "hiltwin?");
  const std::string rule = Record({OddEmitter("rule_kind")});
  EXPECT_THAT(ErrorOf(rule),
              HasSubstr("(hiltwin:qos_rule, vpid " + std::to_string(recording_.pids.at(0)) +
                        "): unknown QoS rule kind 9"));
  const std::string state = Record({OddEmitter("state_code")});
  EXPECT_THAT(ErrorOf(state), HasSubstr("event #4 in time order (hiltwin:state_transition"));
  EXPECT_THAT(ErrorOf(state), HasSubstr("unknown to code 42 (known: 0 to 7)"));
}

TEST_F(CtfReaderTest, CyclesOutOfOrderAreRefusedNamingTheEvent) {
  const std::string dir = Record({OddEmitter("k_order")});
  EXPECT_EQ(ErrorOf(dir), dir + ": event #4 in time order (hiltwin:cycle, vpid " +
                              std::to_string(recording_.pids.at(0)) +
                              "): cycle k = 0 after k = 1; a process's cycles must come in "
                              "increasing k");
}

TEST_F(CtfReaderTest, AProcessesSecondRunIsLeftOut) {
  const std::string dir = Record({OddEmitter("two_runs")});
  const TimingTrace trace = ReadCtfTrace(dir);
  EXPECT_EQ(trace.cycles.size(), 2U);
  EXPECT_EQ(trace.other_runs, 1U);
  EXPECT_EQ(trace.other_processes, 0U);
  EXPECT_TRUE(trace.complete);
}

}  // namespace
}  // namespace hiltwin::analysis
