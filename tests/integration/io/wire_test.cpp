// The wire backend between two real processes: this test is the ECS, hiltwin_io_wire_peer the
// twin (or the other way round). Values cross, the ECS sees the twin's 1–2 period delay (thesis
// §3.7), a killed peer is detected by its heartbeat, either side may start first and restart.
// Wall-clock checks leave room for a noisy shared machine: the twin runs at 50 Hz (20 ms) so
// scheduling jitter is small against a period, and single outliers are tolerated.
#include <signal.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/kernel_glue/clock.h"
#include "fakes/process.h"

namespace hiltwin::io {
namespace {

constexpr double kTwinRateHz = 50.0;
constexpr std::int64_t kTwinPeriodNs = 20'000'000;
constexpr std::int64_t kEcsPeriodNs = 200'000;

std::string UniqueName(const char* tag) {
  return std::string("itest-") + tag + "-" + std::to_string(::getpid());
}

pid_t StartPeer(const char* side, const std::string& name, double rate_hz = kTwinRateHz) {
  return test::Spawn({HILTWIN_WIRE_PEER, side, name, std::to_string(rate_hz)});
}

/// ECS-side loop helper: exchanges every kEcsPeriodNs until `done` says stop or the timeout.
template <typename Done>
bool Poll(IcoBoard& ecs, const std::array<std::int32_t, kChannels>& pwm, EcsInputs& in,
          ExchangeStatus& last, std::int64_t timeout_ns, Done done) {
  kernel_glue::MonotonicClock clock;
  const std::int64_t end = clock.NowNs() + timeout_ns;
  while (clock.NowNs() < end) {
    last = ecs.Exchange(pwm, in);
    if (done(last, in, clock.NowNs())) return true;
    clock.SleepUntilNs(clock.NowNs() + kEcsPeriodNs);
  }
  return false;
}

bool PeerAlive(const ExchangeStatus& s) { return s.ok() && !s.peer_absent; }

TEST(WireBackend, ValuesCrossAndTheEcsSeesTheTwinDelay) {
  const std::string name = UniqueName("delay");
  WireBus::Unlink(name);
  const pid_t peer = StartPeer("twin", name);  // the peer starts first and creates the segment
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  WireBus bus(name, Image::kIcoboard);
  IcoBoard ecs(bus);
  ASSERT_TRUE(ecs.Init(kEcsPeriodNs).ok);
  EcsInputs in;
  ExchangeStatus status;
  ASSERT_TRUE(Poll(ecs, {0, 0, 0, 0}, in, status, 5'000'000'000,
                   [](const ExchangeStatus& s, const EcsInputs&, std::int64_t) { return PeerAlive(s); }))
      << status.reason;

  std::vector<double> first_change_periods;
  std::vector<double> complete_periods;
  kernel_glue::MonotonicClock clock;
  for (int round = 0; round < 6; ++round) {
    const std::int32_t from = round % 2 == 0 ? 0 : 1000;
    const std::int32_t to = 1000 - from;
    // Settle at `from` (every channel: the twin echoes each channel's PWM).
    const std::array<std::int32_t, kChannels> settle = {from, from / 2, -from, from / 4};
    ASSERT_TRUE(Poll(ecs, settle, in, status, 3'000'000'000,
                     [&](const ExchangeStatus& s, const EcsInputs& i, std::int64_t) {
                       return s.ok() && i.counts == std::array<std::int32_t, kChannels>{from, from / 2, -from, from / 4};
                     }))
        << "values did not cross: " << in.counts[0] << " " << in.counts[1] << " " << in.counts[2]
        << " " << in.counts[3] << " " << status.reason;
    const std::array<std::int32_t, kChannels> step = {to, to / 2, -to, to / 4};
    const std::int64_t t_change = clock.NowNs();
    std::int64_t t_first = 0;
    std::int64_t t_complete = 0;
    ASSERT_TRUE(Poll(ecs, step, in, status, 3'000'000'000,
                     [&](const ExchangeStatus& s, const EcsInputs& i, std::int64_t now) {
                       if (!s.ok()) return false;
                       if (t_first == 0 && i.counts[0] != from) t_first = now;
                       if (i.counts == step) {
                         t_complete = now;
                         return true;
                       }
                       return false;
                     }))
        << status.reason;
    first_change_periods.push_back(static_cast<double>(t_first - t_change) / kTwinPeriodNs);
    complete_periods.push_back(static_cast<double>(t_complete - t_change) / kTwinPeriodNs);
  }
  test::KillAndWait(peer, SIGTERM);

  std::vector<double> sorted = first_change_periods;
  std::sort(sorted.begin(), sorted.end());
  const double median = (sorted[2] + sorted[3]) / 2;
  for (std::size_t r = 0; r < first_change_periods.size(); ++r) {
    std::printf("round %zu: first change after %.2f twin periods, complete after %.2f\n", r,
                first_change_periods[r], complete_periods[r]);
    // Pulses can start no earlier than the twin's next sampling moment after the one that read
    // the new PWM; allow jitter of the peer's wake-ups on a shared machine.
    EXPECT_GT(first_change_periods[r], 0.5);
    EXPECT_LT(first_change_periods[r], 3.5);
    // The pulses are spread over the twin period that follows: completion comes later.
    EXPECT_GT(complete_periods[r] - first_change_periods[r], 0.5);
  }
  EXPECT_GE(median, 0.9);
  EXPECT_LE(median, 2.3);
}

TEST(WireBackend, AKilledPeerIsDetectedByItsHeartbeat) {
  const std::string name = UniqueName("kill");
  WireBus::Unlink(name);
  WireBus bus(name, Image::kIcoboard);  // this side starts first
  IcoBoard ecs(bus);
  ASSERT_TRUE(ecs.Init(kEcsPeriodNs).ok);
  EcsInputs in;
  ExchangeStatus status = ecs.Exchange({0, 0, 0, 0}, in);
  EXPECT_TRUE(status.ok());
  EXPECT_TRUE(status.peer_absent);  // no twin yet: not a fault, values idle
  EXPECT_EQ(bus.PeerStatus().result, BusResult::kPeerAbsent);

  const pid_t peer = StartPeer("twin", name);
  ASSERT_TRUE(Poll(ecs, {0, 0, 0, 0}, in, status, 5'000'000'000,
                   [](const ExchangeStatus& s, const EcsInputs&, std::int64_t) { return PeerAlive(s); }));

  test::KillAndWait(peer, SIGKILL);  // a crash: no chance to detach
  kernel_glue::MonotonicClock clock;
  const std::int64_t t_kill = clock.NowNs();
  std::int64_t t_detected = 0;
  ASSERT_TRUE(Poll(ecs, {0, 0, 0, 0}, in, status, 5'000'000'000,
                   [&](const ExchangeStatus& s, const EcsInputs&, std::int64_t now) {
                     t_detected = now;
                     return s.code == ExchangeStatus::Code::kFault;
                   }));
  EXPECT_NE(std::string(status.reason).find("twin process stopped updating its heartbeat"),
            std::string::npos)
      << status.reason;
  // Timeout: max(100 ms, 20 twin periods = 400 ms); the heartbeat may be up to one period old.
  const double detected_ms = static_cast<double>(t_detected - t_kill) / 1e6;
  std::printf("killed twin detected after %.0f ms\n", detected_ms);
  EXPECT_LT(detected_ms, 2000.0);
  EXPECT_GT(detected_ms, 300.0);
  EXPECT_GT(ecs.counters().faults, 0U);

  // A restarted twin is picked up again without restarting the ECS.
  const pid_t again = StartPeer("twin", name);
  EXPECT_TRUE(Poll(ecs, {0, 0, 0, 0}, in, status, 5'000'000'000,
                   [](const ExchangeStatus& s, const EcsInputs&, std::int64_t) { return PeerAlive(s); }))
      << status.reason;
  test::KillAndWait(again, SIGTERM);
  // A peer that stops cleanly detaches, and that is reported too.
  status = ecs.Exchange({0, 0, 0, 0}, in);
  EXPECT_EQ(status.code, ExchangeStatus::Code::kFault);
  EXPECT_NE(std::string(status.reason).find("detached"), std::string::npos) << status.reason;
}

TEST(WireBackend, TheLastProcessToLeaveRemovesTheSegment) {
  const std::string name = UniqueName("cleanup");
  WireBus::Unlink(name);
  const std::string path = "/dev/shm" + WireBus::SegmentName(name);
  const pid_t crashed = StartPeer("twin", name);
  {
    WireBus bus(name, Image::kIcoboard);
    IcoBoard ecs(bus);
    ASSERT_TRUE(ecs.Init(kEcsPeriodNs).ok);
    EcsInputs in;
    ExchangeStatus status;
    ASSERT_TRUE(Poll(ecs, {0, 0, 0, 0}, in, status, 5'000'000'000,
                     [](const ExchangeStatus& s, const EcsInputs&, std::int64_t) { return PeerAlive(s); }));
    test::KillAndWait(crashed, SIGKILL);
    EXPECT_EQ(::access(path.c_str(), F_OK), 0);
  }
  EXPECT_NE(::access(path.c_str(), F_OK), 0) << path << " was left behind";
}

TEST(WireBackend, TheTwinSideSeesTheEcsPwmAndASecondTwinIsRefused) {
  const std::string name = UniqueName("twin");
  WireBus::Unlink(name);
  const pid_t peer = StartPeer("ecs", name, 500.0);
  WireBus bus(name, Image::kIcoboardInverse);
  IcoBoardInverse twin(bus);
  ASSERT_TRUE(twin.Init(kTwinPeriodNs).ok);
  TwinInputs in;
  kernel_glue::MonotonicClock clock;
  const std::int64_t end = clock.NowNs() + 5'000'000'000;
  ExchangeStatus status;
  while (clock.NowNs() < end) {
    status = twin.Exchange({0, 0, 0, 0}, in);
    if (PeerAlive(status) && in.pwm[3] == 400) break;
    clock.SleepUntilNs(clock.NowNs() + 1'000'000);
  }
  EXPECT_EQ(in.pwm, (std::array<std::int32_t, kChannels>{100, 200, 300, 400})) << status.reason;
  EXPECT_THROW(WireBus(name, Image::kIcoboardInverse), std::runtime_error);
  test::KillAndWait(peer, SIGTERM);
}

}  // namespace
}  // namespace hiltwin::io
