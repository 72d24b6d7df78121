// The RELbot twin in the real run assembly (runtime::RunSession, exactly as `hiltwin run` uses
// it): executive, lifecycle, mock FPGA link, RELbot model, QoS monitor, tracepoints and CSV
// logger and timing log run 20,000 cycles on the loop thread without a single heap allocation after start.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "fakes/alloc_counter.h"
#include "fakes/loop_allocations.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/profile_pwm_source.h"
#include "hiltwin/relbot/relbot_channels.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/relbot_twin.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

constexpr std::uint64_t kCycles = 20'000;

using test::LoopAllocations;

struct TwinRig {
  explicit TwinRig(const std::string& log_path)
      : profile(OpenLoopProfile()),
        pwm_source(profile, 1000.0, 4000.0),
        backend(io::OpenBackend("mock", io::BackendOptions{})),
        driver(backend->bus()),
        params(DefaultRelbotParams()),
        twin(driver, params, Integrator::kRk4, 2.5e-4) {
    backend->emulated_board()->SetPwmSource(&pwm_source);
    EXPECT_TRUE(driver.Init(250'000).ok);
    runtime::SessionConfig config;
    config.task_name = "RELbot twin";
    config.io = "mock";
    config.clock = runtime::ClockKind::kVirtual;
    config.executive.period_ns = 250'000;
    config.executive.max_cycles = kCycles;
    config.qos.rules = qos::DefaultRules();
    config.qos.planned_cycles = kCycles;
    config.injector.Add(runtime::ParseOverrunInjection("every=997,extra-us=400"));  // miss path
    config.log = runtime::LogConfig{log_path, 1};
    config.timing_log_path = log_path + ".timing";
    session.emplace(std::move(config), twin.task());
  }

  InputProfile profile;
  ProfilePwmSource pwm_source;
  std::unique_ptr<io::IoBackend> backend;
  io::IcoBoardInverse driver;
  RelbotParams params;
  RelbotTwin twin;
  std::optional<runtime::RunSession> session;
};

std::string TempLog(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string(name) + std::to_string(getpid()) + ".csv"))
      .string();
}

TEST(TwinLoop, RunsTwentyThousandCyclesWithoutAllocating) {
  const std::string log_path = TempLog("hiltwin_twin_loop_");
  TwinRig rig(log_path);
  LoopAllocations allocations;
  rig.session->SetLoopThreadHooks(&allocations);
  const runtime::RunReport report = rig.session->Run();
  EXPECT_EQ(allocations.count, 0U) << "malloc counted: " << test::MallocIsCounted();
  // The loop really did the work: the robot moved, misses were injected, rows were logged.
  EXPECT_EQ(report.cycles_run, kCycles);
  EXPECT_GT(report.misses.deadline_misses, 0U);
  EXPECT_EQ(report.misses.releases, report.releases);  // every release is in the one ledger
  EXPECT_EQ(report.stop_reason, lifecycle::StopReason::kFinished);
  EXPECT_EQ(report.final_state, lifecycle::State::kStopped);
  EXPECT_NE(rig.twin.model().Outputs().wheel_left_m, 0.0);
  EXPECT_EQ(rig.twin.model().steps(), kCycles);
  EXPECT_EQ(report.link.io_errors, 0U);
  ASSERT_TRUE(report.log.has_value());
  EXPECT_EQ(report.log->rows_written, kCycles);
  ASSERT_TRUE(report.timing_log.has_value());
  EXPECT_EQ(report.timing_log->rows_written, kCycles);
  EXPECT_TRUE(report.outputs_safe);
  std::filesystem::remove(log_path);
  std::filesystem::remove(log_path + ".timing");
}

TEST(TwinLoop, EncoderPositionsReachTheBoardAndTheSafeOutputsStopThePulses) {
  const std::string log_path = TempLog("hiltwin_twin_hold_");
  TwinRig rig(log_path);
  const runtime::RunReport report = rig.session->Run();  // ends with the safe outputs
  ASSERT_TRUE(report.outputs_safe);
  const auto& sent = rig.twin.task().encoder_next();
  // The counts are the wheel travel at the encoder's scale: counts per motor turn times motor
  // turns per wheel turn over the wheel's circumference (about 12 732 counts/m by default).
  const RelbotOutputs wheels = rig.twin.outputs();
  const RelbotParams& p = rig.params;
  const double counts_per_m = p.gear_ratio_motor_rev_per_wheel_rev *
                              p.encoder_counts_per_motor_rev /
                              (2.0 * 3.14159265358979323846 * p.wheel_radius_m);
  ASSERT_GT(counts_per_m, 1000.0);
  ASSERT_GT(std::abs(wheels.wheel_left_m), 0.05);  // the profile moved the wheel
  EXPECT_NEAR(sent[kLeftChannel], wheels.wheel_left_m * counts_per_m, 1.0);
  EXPECT_NEAR(sent[kRightChannel], wheels.wheel_right_m * counts_per_m, 1.0);
  // The safe outputs repeat what the last live exchange sent (the step before the last one's
  // positions), so the emulator settles there and emits no more pulses: a robot at rest.
  const auto& held = rig.twin.task().encoder_sent();
  EXPECT_NEAR(held[kLeftChannel], sent[kLeftChannel], 20);  // one 250 µs step of travel
  const io::EmulatedFpga& board = *rig.backend->emulated_board();
  const io::EncoderEmulator& left = board.encoder(kLeftChannel);
  const std::int64_t now_ns = board.time_ns();
  EXPECT_EQ(left.PositionAt(now_ns + 10 * 250'000), io::WrapToRelative(held[kLeftChannel]));
  // Pulses already due finish within one period; after that the emulator is still.
  EXPECT_EQ(left.PositionAt(now_ns + 250'000), left.PositionAt(now_ns + 10 * 250'000));
  std::filesystem::remove(log_path);
  std::filesystem::remove(log_path + ".timing");
}

}  // namespace
}  // namespace hiltwin::app
