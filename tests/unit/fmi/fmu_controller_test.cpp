// FMUs as controllers (fmu_controller.h) against tests/fmus/pid.fmu, a position PID per wheel
// compiled from C in this build: ports, units and the run report's facts (name, file, content
// hash, GUID), the control law against a hand computation (a setpoint step: P, I and D after
// 1, 2 and 3 steps), the `fmu` kind, the refusals (Model Exchange only, no output, an Integer
// output, --gains), a failing step, no allocation in Step, and the thesis's 2.5 m closed loop
// against the RELbot model.
#include "hiltwin/fmi/fmu_controller.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "fakes/controller_loop.h"
#include "hiltwin/controller/content_hash.h"
#include "hiltwin/controller/controller_registry.h"
#include "test_fmus.h"

namespace hiltwin::fmi {
namespace {

using controller::Controller;
using controller::ControllerError;
using controller::ControllerInfo;
using controller::ControllerOptions;
using controller::ControllerStatus;
using test::TestFmu;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kControllerStepS = 0.001;

std::unique_ptr<Controller> OpenPidController(const std::string& name = "pid") {
  return OpenFmuController(TestFmu(name), {});
}

std::string ControllerOpenError(const std::string& name, const ControllerOptions& options = {}) {
  try {
    static_cast<void>(OpenFmuController(TestFmu(name), options));
  } catch (const ControllerError& error) {
    return error.what();
  }
  ADD_FAILURE() << name << ".fmu opened as a controller";
  return {};
}

TEST(FmuController, InfoHasThePortsUnitsAndWhatTracesTheResultToTheFile) {
  const std::unique_ptr<Controller> controller = OpenPidController();
  const ControllerInfo& info = controller->Info();
  const std::string path = TestFmu("pid").string();
  EXPECT_EQ(info.spec, "fmu:" + path);
  EXPECT_EQ(info.kind, "FMI 2.0 co-simulation");
  EXPECT_EQ(info.name, "PositionPid");  // modelName
  EXPECT_EQ(info.file, path);
  // The hash of the .fmu's bytes, as sha256sum prints it.
  EXPECT_EQ(info.content_sha256, controller::Sha256HexOfFile(path));
  EXPECT_THAT(info.content_sha256, ::testing::MatchesRegex("[0-9a-f]{64}"));
  ASSERT_EQ(info.inputs.size(), 4U);
  EXPECT_EQ(info.inputs[0].name, "setpoint_left_m");
  EXPECT_EQ(info.inputs[2].name, "wheel_left_m");
  EXPECT_EQ(info.inputs[2].unit, "m");
  ASSERT_EQ(info.outputs.size(), 2U);  // the parameters are not ports
  EXPECT_EQ(info.outputs[0].name, "duty_left");
  EXPECT_EQ(info.outputs[0].unit, "1");
  EXPECT_EQ(info.model_step_s, kControllerStepS);  // DefaultExperiment stepSize
  EXPECT_FALSE(info.step_is_fixed);
  std::string details;
  for (const auto& [key, value] : info.details) details += key + "=" + value + "\n";
  EXPECT_THAT(details, HasSubstr("guid={hiltwin-test-fmu-pid}\n"));
  EXPECT_THAT(details, HasSubstr("generationTool=hiltwin tests/fmus\n"));
}

// A setpoint step of 1 mm on the left wheel while it moves 0, 0.2 and 0.5 mm; the right wheel
// 2 mm behind and still. The hand computation of position_pid.h's law with the ECS's gains.
TEST(FmuController, SetpointStepGivesPIAndDTermsOfTheHandComputation) {
  const std::unique_ptr<Controller> controller = OpenPidController();
  controller->Start(kControllerStepS);
  hiltwin::test::HandPid left(kControllerStepS);
  const std::array<double, 3> travel_m{0.0, 0.2e-3, 0.5e-3};
  // P + I + D: 0.1 + 0.001; 0.08 + 0.0018 - 500 * 0.2e-3; 0.05 + 0.0023 + (5/6) D' - 0.15.
  const std::array<double, 3> expected{0.101, -0.0182, 0.05 + 0.0023 - 0.1 * 5.0 / 6.0 - 0.15};
  std::array<double, 2> out{};
  for (std::size_t k = 0; k < travel_m.size(); ++k) {
    const std::array<double, 4> in{1e-3, -2e-3, travel_m[k], 0.0};
    ASSERT_TRUE(controller->Step(in, out).ok()) << "step " << k + 1;
    EXPECT_NEAR(out[0], expected[k], 1e-12) << "step " << k + 1;
    EXPECT_NEAR(out[0], left.Step(1e-3, travel_m[k]), 1e-12) << "step " << k + 1;
  }
  EXPECT_NEAR(out[1], 100.0 * -2e-3 + 3 * 1000.0 * kControllerStepS * -2e-3,
              1e-12);  // P + 3 steps of I
  controller->Finish();
  controller->Finish();
}

// The communication step is the controller's period: at 2 kHz the integral and the derivative
// filter use T = 0.5 ms (the FMU takes any step, unlike 20-sim code).
TEST(FmuController, RunsAtTheStepItIsStartedWith) {
  const std::unique_ptr<Controller> controller = OpenPidController();
  controller->Start(0.0005);
  hiltwin::test::HandPid hand(0.0005);
  std::array<double, 2> out{};
  for (const double travel_m : {0.0, 0.1e-3, 0.3e-3}) {
    const std::array<double, 4> in{1e-3, 0.0, travel_m, 0.0};
    ASSERT_TRUE(controller->Step(in, out).ok());
    EXPECT_NEAR(out[0], hand.Step(1e-3, travel_m), 1e-12);
  }
  EXPECT_THROW(controller->Start(0.0), ControllerError);
}

TEST(FmuController, TheFmuKindOpensItFromTheSpec) {
  static const bool kRegistered = [] {
    RegisterFmuControllerKind();
    return true;
  }();
  ASSERT_TRUE(kRegistered);
  const std::string spec = "fmu:" + TestFmu("pid").string();
  const std::unique_ptr<Controller> controller = controller::MakeController(spec, {});
  EXPECT_EQ(controller->Info().spec, spec);
  EXPECT_EQ(controller->Info().name, "PositionPid");
}

TEST(FmuController, ModelExchangeOnlyIsRefused) {
  EXPECT_THAT(ControllerOpenError("bad_pid_me_only"),
              HasSubstr("bad_pid_me_only.fmu: modelDescription.xml:5: a ModelExchange-only FMU"));
}

TEST(FmuController, AnFmuWithoutOutputsIsRefused) {
  EXPECT_EQ(ControllerOpenError("bad_pid_no_outputs"),
            TestFmu("bad_pid_no_outputs").string() +
                ": the FMU has no Real variable of causality \"output\": a controller needs at "
                "least one (a duty): export its commands as outputs");
}

// Line 49: where the variable's <ScalarVariable ...> start tag ends in the configured
// pid.xml.in (the line libxml2 gives a node, as in the plant's messages).
TEST(FmuController, ANonRealOutputIsRefusedWithItsLine) {
  EXPECT_EQ(ControllerOpenError("bad_pid_integer_output"),
            TestFmu("bad_pid_integer_output").string() +
                ": modelDescription.xml:49: the output 'mode' is of type Integer: a "
                "controller's outputs are duties, Real only: export it as a Real, or give it "
                "causality \"local\" if it is not a command");
}

TEST(FmuController, GainsAreRefusedNotIgnored) {
  ControllerOptions options;
  options.gains_path = "g.toml";
  EXPECT_THAT(ControllerOpenError("pid", options),
              StartsWith("--gains g.toml cannot apply to fmu:" + TestFmu("pid").string() +
                         ": an FMU brings its own parameters"));
}

TEST(FmuController, NotAnFmuIsAControllerErrorNamingTheFile) {
  EXPECT_THAT(ControllerOpenError("bad_corrupt"), HasSubstr("bad_corrupt.fmu"));
}

// A controller FMU whose doStep fails from step 100 on (the lag_fail variant: the mechanism is
// the same for any FMU): the step reports an error with the call that failed, and stays failed.
TEST(FmuController, AFailingDoStepIsAnErrorStatusNamingTheCall) {
  const std::unique_ptr<Controller> controller = OpenFmuController(TestFmu("lag_fail"), {});
  controller->Start(kControllerStepS);
  const std::array<double, 1> in{1.0};
  std::array<double, 1> out{};
  int ok_steps = 0;
  ControllerStatus status;
  while ((status = controller->Step(in, out)).ok() && ok_steps < 1000) ++ok_steps;
  EXPECT_EQ(ok_steps, 100);
  EXPECT_STREQ(status.reason, "fmi2DoStep returned fmi2Error");
  EXPECT_FALSE(controller->Step(in, out).ok());
}

TEST(FmuController, StepAllocatesNothing) {
  const std::unique_ptr<Controller> controller = OpenPidController();
  controller->Start(kControllerStepS);
  const std::array<double, 4> in{0.01, 0.02, 0.0, 0.0};
  const hiltwin::test::StepAllocations counted =
      hiltwin::test::CountStepAllocations(*controller, in);
  EXPECT_EQ(counted.not_ok, 0);
  EXPECT_EQ(counted.allocations, 0U)
      << (hiltwin::test::MallocIsCounted() ? "malloc and new counted" : "operator new counted");
}

// Thesis §7.2: the 2.5 m move with the error below 3 mm.
TEST(FmuController, TracksTheTwoAndAHalfMetreMoveWithinTheThesisBound) {
  const std::unique_ptr<Controller> controller = OpenPidController();
  const hiltwin::test::ClosedLoopFigures run = hiltwin::test::RunRelbotClosedLoop(*controller);
  hiltwin::test::RecordClosedLoopFigures(run);
  EXPECT_EQ(run.steps_not_ok, 0U);
  EXPECT_LT(run.max_abs_error_left_m, 1.5e-3);
  EXPECT_LT(run.max_abs_error_right_m, 1.5e-3);
  EXPECT_GT(run.max_abs_error_left_m, 0.5e-3);  // a real figure, not a dead loop
  EXPECT_LT(std::abs(run.final_error_left_m), 1e-4);
  EXPECT_LT(std::abs(run.final_error_right_m), 1e-4);
  EXPECT_LT(run.max_abs_duty, 0.85);
}

}  // namespace
}  // namespace hiltwin::fmi
