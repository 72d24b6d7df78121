// The whole twin loop as `hiltwin run` assembles it — executive, mock FPGA link, RELbot model,
// QoS monitor, tracepoints and CSV logger — runs without a single heap allocation after start.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "fakes/alloc_counter.h"
#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/app_relbot/twin_task.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/scheduler/executive.h"

namespace hiltwin::app {
namespace {

struct TwinRig {
  explicit TwinRig(const std::string& log_path)
      : profile(OpenLoopProfile()),
        pwm_source(profile, 1000.0),
        backend(io::OpenBackend("mock", io::BackendOptions{})),
        driver(backend->bus(), &clock),
        params(DefaultRelbotParams()),
        model(params, Integrator::kRk4, 2.5e-4),
        geometry(WheelGeometryOf(params)),
        monitor(MakeQos()),
        executive(clock, MakeExecutive()),
        task(driver, model, geometry, clock, injector, lifecycle),
        qos_observer(monitor) {
    backend->emulated_board()->SetPwmSource(&pwm_source);
    EXPECT_TRUE(driver.Init(250'000).ok);
    tracing::CsvLoggerConfig log_config;
    log_config.path = log_path;
    log_config.columns = LogObserver::Columns();
    logger = std::make_unique<tracing::CsvLogger>(log_config);
    log_observer = std::make_unique<LogObserver>(*logger, task);
    executive.AddObserver(qos_observer);
    executive.AddObserver(*log_observer);
    injector.Add(ParseOverrunInjection("every=997,extra-us=400"));  // exercise the miss path
  }
  static qos::QosConfig MakeQos() {
    qos::QosConfig c;
    c.rules = qos::DefaultRules();
    c.planned_cycles = 20'000;
    return c;
  }
  static scheduler::ExecutiveConfig MakeExecutive() {
    scheduler::ExecutiveConfig c;
    c.period_ns = 250'000;
    c.max_cycles = 20'000;
    return c;
  }

  kernel_glue::VirtualClock clock;
  InputProfile profile;
  ProfilePwmSource pwm_source;
  std::unique_ptr<io::IoBackend> backend;
  io::IcoBoardInverse driver;
  RelbotParams params;
  RelbotModel model;
  io::WheelGeometry geometry;
  OverrunInjector injector;
  statemachine::Lifecycle lifecycle;
  qos::QosMonitor monitor;
  scheduler::Executive executive;
  TwinTask task;
  QosObserver qos_observer;
  std::unique_ptr<tracing::CsvLogger> logger;
  std::unique_ptr<LogObserver> log_observer;
};

TEST(TwinLoop, RunsTwentyThousandCyclesWithoutAllocating) {
  const std::string log_path =
      (std::filesystem::temp_directory_path() / ("hiltwin_twin_loop_" + std::to_string(getpid()) + ".csv")).string();
  TwinRig rig(log_path);
  rig.logger->Start();
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount count;
    rig.executive.Run(rig.task);
    allocations = count.count();
  }
  rig.logger->Stop();
  EXPECT_EQ(allocations, 0U);
  // The loop really did the work: the robot moved, misses were injected, rows were logged.
  EXPECT_EQ(rig.executive.stats().cycles_run, 20'000U);
  EXPECT_GT(rig.executive.stats().deadline_misses, 0U);
  EXPECT_EQ(rig.monitor.cycles_recorded(), rig.executive.stats().releases);
  EXPECT_NE(rig.model.Outputs().wheel_left_m, 0.0);
  EXPECT_EQ(rig.task.io_errors(), 0U);
  EXPECT_EQ(rig.logger->rows_written(), 20'000U);
  std::filesystem::remove(log_path);
}

TEST(TwinLoop, EncoderPositionsReachTheBoardAndHoldOutputsStopsThePulses) {
  const std::string log_path =
      (std::filesystem::temp_directory_path() / ("hiltwin_twin_hold_" + std::to_string(getpid()) + ".csv")).string();
  TwinRig rig(log_path);
  rig.executive.Run(rig.task);
  const auto& sent = rig.task.last().encoder_counts;
  // The counts are the wheel travel at the encoder's scale: counts per motor turn times motor
  // turns per wheel turn over the wheel's circumference (about 12 732 counts/m by default).
  const RelbotOutputs& wheels = rig.task.last().outputs;
  const RelbotParams& p = rig.params;
  const double counts_per_m = p.gear_ratio_motor_rev_per_wheel_rev *
                              p.encoder_counts_per_motor_rev /
                              (2.0 * 3.14159265358979323846 * p.wheel_radius_m);
  ASSERT_GT(counts_per_m, 1000.0);
  ASSERT_GT(std::abs(wheels.wheel_left_m), 0.05);  // the profile moved the wheel
  EXPECT_NEAR(sent[kLeftChannel], wheels.wheel_left_m * counts_per_m, 1.0);
  EXPECT_NEAR(sent[kRightChannel], wheels.wheel_right_m * counts_per_m, 1.0);
  const io::ExchangeStatus hold = rig.task.HoldOutputs();
  EXPECT_TRUE(hold.ok()) << hold.reason;
  // After holding, the emulator settles on the last position sent and emits no more pulses.
  const io::EmulatedFpga& board = *rig.backend->emulated_board();
  const io::EncoderEmulator& left = board.encoder(kLeftChannel);
  const std::int64_t now_ns = board.time_ns();
  EXPECT_EQ(left.PositionAt(now_ns + 10 * 250'000), io::WrapToRelative(sent[kLeftChannel]));
  // Pulses already due finish within one period; after that the emulator is still.
  EXPECT_EQ(left.PositionAt(now_ns + 250'000), left.PositionAt(now_ns + 10 * 250'000));
  rig.logger->Stop();
  std::filesystem::remove(log_path);
}

}  // namespace
}  // namespace hiltwin::app
