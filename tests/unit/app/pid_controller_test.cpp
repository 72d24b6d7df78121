// The built-in PID as a controller (`--controller pid`): two PositionPids behind the controller
// interface, its registration, and the RELbot's controller map, built in and shipped as
// relbot/ecs_controller_map.toml.
#include "hiltwin/relbot/pid_controller.h"

#include <gtest/gtest.h>

#include <array>

#include "fakes/test_paths.h"
#include "hiltwin/controller/controller_registry.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/relbot_channels.h"
#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {
namespace {

TEST(PidController, StepsAsOnePositionPidPerWheel) {
  const PidGains gains = DefaultEcsGains();
  PidController pid(gains);
  pid.Start(1e-3);
  PositionPid left(gains, 1e-3);
  PositionPid right(gains, 1e-3);
  std::array<double, 2> out{};
  for (int k = 0; k < 50; ++k) {
    const double t = 1e-3 * k;
    const std::array<double, 4> in = {0.01 * t, -0.02 * t, 0.003 * t * t, -0.001 * t};
    ASSERT_TRUE(pid.Step(in, out).ok());
    ASSERT_EQ(out[0], left.Step(in[0], in[2])) << k;
    ASSERT_EQ(out[1], right.Step(in[1], in[3])) << k;
  }
  EXPECT_EQ(pid.Info().kind, "built-in");
  EXPECT_EQ(pid.Info().spec, "pid");
  EXPECT_EQ(pid.Info().file, "");
}

TEST(PidController, IsRegisteredAsPidWithItsGainsFile) {
  RegisterPidController();
  controller::ControllerOptions options;
  options.gains_path = HILTWIN_ECS_GAINS_TOML;
  const std::unique_ptr<controller::Controller> pid = controller::MakeController("pid", options);
  EXPECT_EQ(static_cast<const PidController&>(*pid).gains().kp_duty_per_m,
            LoadEcsGains(HILTWIN_ECS_GAINS_TOML).kp_duty_per_m);
  options.gains_path = "/nonexistent/gains.toml";
  try {
    static_cast<void>(controller::MakeController("pid", options));
    FAIL() << "no error";
  } catch (const controller::ControllerError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/gains.toml"), std::string::npos)
        << e.what();
  }
}

TEST(PidController, TheShippedControllerMapIsTheBuiltInOne) {
  const io::WheelGeometry geometry = WheelGeometryOf(LoadRelbotParams(HILTWIN_RELBOT_TOML));
  const PidController pid(DefaultEcsGains());
  const controller::BoundControllerMap shipped = controller::BindControllerMap(
      controller::LoadControllerMap(HILTWIN_ECS_CONTROLLER_MAP_TOML), pid);
  const controller::BoundControllerMap built_in =
      controller::BindControllerMap(RelbotControllerMap(geometry), pid);
  ASSERT_EQ(shipped.encoders.size(), built_in.encoders.size());
  for (std::size_t i = 0; i < shipped.encoders.size(); ++i) {
    EXPECT_EQ(shipped.encoders[i].channel_index, built_in.encoders[i].channel_index);
    EXPECT_EQ(shipped.encoders[i].input_index, built_in.encoders[i].input_index);
    // Exactly: the ECS's figures with the file must be the default run's, bit for bit.
    EXPECT_EQ(shipped.encoders[i].counts_per_unit, built_in.encoders[i].counts_per_unit);
    EXPECT_EQ(built_in.encoders[i].counts_per_unit, io::CountsPerMetre(geometry));
  }
  ASSERT_EQ(shipped.setpoints.size(), built_in.setpoints.size());
  for (std::size_t i = 0; i < shipped.setpoints.size(); ++i) {
    EXPECT_EQ(shipped.setpoints[i].column_index, built_in.setpoints[i].column_index);
    EXPECT_EQ(shipped.setpoints[i].input_index, built_in.setpoints[i].input_index);
    EXPECT_EQ(shipped.setpoints[i].tracked_encoder, built_in.setpoints[i].tracked_encoder);
    EXPECT_EQ(shipped.setpoints[i].on_encoder_grid, built_in.setpoints[i].on_encoder_grid);
  }
  ASSERT_EQ(shipped.pwm.size(), built_in.pwm.size());
  for (std::size_t i = 0; i < shipped.pwm.size(); ++i) {
    EXPECT_EQ(shipped.pwm[i].channel_index, built_in.pwm[i].channel_index);
    EXPECT_EQ(shipped.pwm[i].output_index, built_in.pwm[i].output_index);
    EXPECT_EQ(shipped.pwm[i].gain, built_in.pwm[i].gain);
    EXPECT_EQ(shipped.pwm[i].duty_limit, built_in.pwm[i].duty_limit);
  }
  EXPECT_EQ(shipped.initial_inputs, built_in.initial_inputs);
  // Appendix G: channel 2 is the left wheel, channel 1 the right.
  EXPECT_EQ(built_in.encoders[0].channel_index, kLeftChannel);
  EXPECT_EQ(built_in.pwm[1].channel_index, kRightChannel);
}

}  // namespace
}  // namespace hiltwin::app
