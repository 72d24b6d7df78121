// The C ABI loader with good libraries: what it reports, the example's PD law by hand, the
// entry points' life cycle, a fixed step, no allocation in Step, a step's error and a NaN
// passed on as they are, and a crash in the library ending the process.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "controller_libs.h"
#include "fakes/alloc_counter.h"
#include "fakes/process.h"
#include "hiltwin/controller/abi_controller.h"

namespace hiltwin::controller::test {
namespace {

using ::testing::HasSubstr;

constexpr double kStepS = 0.001;

/// A `#define NAME value` of examples/controller_c_pd/my_pd.c: the test follows the example's
/// tuning instead of repeating it.
double ExampleConstant(const std::string& name) {
  std::ifstream in(hiltwin::test::BesideTest(HILTWIN_MY_PD_C));
  std::stringstream text;
  text << in.rdbuf();
  std::smatch match;
  const std::string source = text.str();
  const std::regex define("#define " + name + " ([-+0-9.eE]+)");
  if (!std::regex_search(source, match, define)) {
    ADD_FAILURE() << "no #define " << name << " in my_pd.c";
    return 0.0;
  }
  return std::stod(match[1].str());
}

double Clamp(double duty) { return std::fmax(-1.0, std::fmin(1.0, duty)); }

std::string Sha256Sum(const std::string& file) {
  const auto result = hiltwin::test::Run({"sha256sum", file});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return result.out.substr(0, 64);
}

TEST(AbiController, ReportsTheLibrarysNamePortsFileAndHash) {
  const std::string lib = Lib("my_pd");
  const auto controller = LoadAbiController(lib);
  const ControllerInfo& info = controller->Info();
  EXPECT_EQ(info.spec, "lib:" + lib);
  EXPECT_EQ(info.kind, "C ABI shared library");
  EXPECT_EQ(info.name, "my_pd");
  EXPECT_EQ(info.file, std::filesystem::path(lib).lexically_normal().string());
  EXPECT_EQ(info.content_sha256, Sha256Sum(lib));
  const std::vector<Port> inputs = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                    {"wheel_left_m", "m"}, {"wheel_right_m", "m"}};
  const std::vector<Port> outputs = {{"duty_left", "1"}, {"duty_right", "1"}};
  ASSERT_EQ(info.inputs.size(), inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    EXPECT_EQ(info.inputs[i].name, inputs[i].name);
    EXPECT_EQ(info.inputs[i].unit, inputs[i].unit);
  }
  ASSERT_EQ(info.outputs.size(), outputs.size());
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    EXPECT_EQ(info.outputs[i].name, outputs[i].name);
    EXPECT_EQ(info.outputs[i].unit, outputs[i].unit);
  }
  EXPECT_EQ(info.model_step_s, 0.0);
  EXPECT_FALSE(info.step_is_fixed);
  ASSERT_FALSE(info.details.empty());
  EXPECT_EQ(info.details[0].first, "ABI version");
  EXPECT_EQ(info.details[0].second, "1");
}

TEST(AbiController, ARelativePathIsReportedAsTypedAndItsFileAsAbsolute) {
  const std::filesystem::path dir = std::filesystem::path(Lib("my_pd")).parent_path();
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const auto controller = LoadAbiController("./my_pd.so");
  std::filesystem::current_path(before);
  EXPECT_EQ(controller->Info().spec, "lib:./my_pd.so");
  EXPECT_EQ(controller->Info().file, (dir / "my_pd.so").lexically_normal().string());
}

TEST(AbiController, TheExampleIsAPdOnTheMeasurementClampedToOne) {
  const double kp = ExampleConstant("KP");
  const double kd = ExampleConstant("KD");
  ASSERT_GT(kp, 0.0);
  ASSERT_GT(kd, 0.0);
  const auto controller = LoadAbiController(Lib("my_pd"));
  controller->Start(kStepS);
  std::vector<double> out(2);
  // First step: no speed yet (one sample), so only the proportional part.
  ASSERT_TRUE(controller->Step(std::vector{0.001, -0.002, 0.0005, 0.0}, out).ok());
  EXPECT_NEAR(out[0], Clamp(kp * 0.0005), 1e-12);
  EXPECT_NEAR(out[1], Clamp(kp * -0.002), 1e-12);
  // The wheels moved 0.1 mm and -0.1 mm in one step: 0.1 m/s each way. The setpoint did not
  // move, so the derivative is the measurement's alone.
  ASSERT_TRUE(controller->Step(std::vector{0.001, -0.002, 0.0006, -0.0001}, out).ok());
  EXPECT_NEAR(out[0], Clamp(kp * (0.001 - 0.0006) - kd * 0.1), 1e-9);
  EXPECT_NEAR(out[1], Clamp(kp * (-0.002 + 0.0001) + kd * 0.1), 1e-9);
  // A setpoint step of a metre saturates at exactly +-1 and kicks nothing else.
  ASSERT_TRUE(controller->Step(std::vector{1.0, -1.0, 0.0006, -0.0001}, out).ok());
  EXPECT_EQ(out[0], 1.0);
  EXPECT_EQ(out[1], -1.0);
}

TEST(AbiController, StartsFromAFreshStateEachStart) {
  const auto controller = LoadAbiController(Lib("my_pd"));
  std::vector<double> first(2);
  std::vector<double> again(2);
  controller->Start(kStepS);
  ASSERT_TRUE(controller->Step(std::vector{0.0, 0.0, 0.0001, 0.0}, first).ok());
  ASSERT_TRUE(controller->Step(std::vector{0.0, 0.0, 0.0002, 0.0}, first).ok());
  controller->Start(kStepS);  // no speed from the last run's measurement
  ASSERT_TRUE(controller->Step(std::vector{0.0, 0.0, 0.0002, 0.0}, again).ok());
  EXPECT_NEAR(again[0], Clamp(ExampleConstant("KP") * -0.0002), 1e-12);
}

TEST(AbiController, CallsEachEntryPointInOrderAndFinishesOnce) {
  const std::string lib = Lib("test_controller");
  auto controller = LoadAbiController(lib);
  const auto base = Calls(lib);  // other tests may have run it in this process
  auto since = [&] {
    auto now = Calls(lib);
    for (std::size_t i = 0; i < now.size(); ++i) now[i] -= base[i];
    return now;
  };
  EXPECT_EQ(since(), (std::array<int, 5>{0, 0, 0, 0, 0}));  // loading calls nothing
  controller->Start(kStepS);
  EXPECT_EQ(since(), (std::array<int, 5>{1, 1, 0, 0, 0}));
  std::vector<double> out(2);
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(controller->Step(std::vector{0.5, 0.25, 0.125, 0.0}, out).ok());
  }
  EXPECT_EQ(out[0], 0.375);  // setpoint minus wheel, per wheel
  EXPECT_EQ(out[1], 0.25);
  controller->Finish();
  controller->Finish();
  EXPECT_EQ(since(), (std::array<int, 5>{1, 1, 3, 1, 1}));
  controller.reset();  // the destructor finds nothing left to finish
  // The library is closed with its last controller: the counters can no longer be read.
  EXPECT_EQ(Calls(lib), (std::array<int, 5>{0, 0, 0, 0, 0}));
}

TEST(AbiController, DestroyingAStartedControllerFinishesAndDestroysIt) {
  const std::string lib = Lib("test_controller");
  auto keep_loaded = LoadAbiController(lib);
  const auto base = Calls(lib);
  {
    auto controller = LoadAbiController(lib);
    controller->Start(kStepS);
  }
  const auto now = Calls(lib);
  EXPECT_EQ(now[3] - base[3], 1);  // finish
  EXPECT_EQ(now[4] - base[4], 1);  // destroy
}

TEST(AbiController, AFixedStepRunsAtItsStepAndNamesTheRateOtherwise) {
  const auto controller = LoadAbiController(Lib("fixed_step"));
  EXPECT_TRUE(controller->Info().step_is_fixed);
  EXPECT_EQ(controller->Info().model_step_s, 0.002);
  try {
    controller->Start(0.001);
    FAIL() << "a 1 ms step was accepted by a library written for 2 ms";
  } catch (const ControllerError& error) {
    const std::string message = error.what();
    EXPECT_THAT(message, HasSubstr("--rate 1000 Hz gives a step of 0.001 s"));
    EXPECT_THAT(message, HasSubstr("written for a step of 0.002 s"));
    EXPECT_THAT(message, HasSubstr("run at --rate 500,"));
  }
  controller->Start(0.002);
  std::vector<double> out(2);
  EXPECT_TRUE(controller->Step(std::vector{1.0, 1.0, 0.0, 0.0}, out).ok());
}

TEST(AbiController, StepAllocatesNothing) {
  const auto controller = LoadAbiController(Lib("my_pd"));
  controller->Start(kStepS);
  std::vector<double> in = {0.0, 0.0, 0.0, 0.0};
  std::vector<double> out(2);
  std::uint64_t allocations = 0;
  {
    const hiltwin::test::ScopedAllocationCount count;
    for (int k = 0; k < 1000; ++k) {
      in[0] = 1e-5 * k;
      in[2] = 0.9e-5 * k;
      if (!controller->Step(in, out).ok()) break;
    }
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0U) << "malloc counted: " << hiltwin::test::MallocIsCounted();
  EXPECT_GT(out[0], 0.0);  // the steps ran
}

TEST(AbiController, AStepErrorStopsWithTheLibrarysText) {
  const auto controller = LoadAbiController(Lib("step_error"));
  controller->Start(kStepS);
  std::vector<double> out(2);
  EXPECT_TRUE(controller->Step(std::vector{0.0, 0.0, 0.0, 0.0}, out).ok());
  EXPECT_TRUE(controller->Step(std::vector{0.0, 0.0, 0.0, 0.0}, out).ok());
  const ControllerStatus status = controller->Step(std::vector{0.0, 0.0, 0.0, 0.0}, out);
  EXPECT_EQ(status.code, ControllerStatus::Code::kError);
  EXPECT_STREQ(status.reason, "wheel runaway: the test library stops at its third step");
  // The library's text was in its state, which destroy() wipes: the reason is a copy.
  controller->Finish();
  EXPECT_STREQ(status.reason, "wheel runaway: the test library stops at its third step");
}

TEST(AbiController, AStepErrorWithoutLastErrorSaysSo) {
  const auto controller = LoadAbiController(Lib("step_error_no_text"));
  controller->Start(kStepS);
  std::vector<double> out(2);
  ControllerStatus status;
  for (int k = 0; k < 3 && status.ok(); ++k) {
    status = controller->Step(std::vector{0.0, 0.0, 0.0, 0.0}, out);
  }
  EXPECT_EQ(status.code, ControllerStatus::Code::kError);
  EXPECT_STREQ(status.reason,
               "the controller's step() returned nonzero and it has no last_error text");
}

TEST(AbiController, StepBeforeStartOrWithTheWrongCountIsAnErrorNotACall) {
  const std::string lib = Lib("test_controller");
  const auto controller = LoadAbiController(lib);
  std::vector<double> out(2);
  EXPECT_STREQ(controller->Step(std::vector{0.0, 0.0, 0.0, 0.0}, out).reason,
               "the controller was not started");
  controller->Start(kStepS);
  const int steps_before = Calls(lib)[2];
  EXPECT_STREQ(controller->Step(std::vector{0.0, 0.0, 0.0}, out).reason,
               "the controller was given the wrong number of values");
  EXPECT_EQ(Calls(lib)[2], steps_before);
}

TEST(AbiController, ANanOutputIsPassedOnUnchanged) {
  // The loader does not judge outputs: the ECS's controller task refuses a NaN duty.
  const auto controller = LoadAbiController(Lib("step_nan"));
  controller->Start(kStepS);
  std::vector<double> out = {7.0, 7.0};
  EXPECT_TRUE(controller->Step(std::vector{0.5, 0.5, 0.25, 0.0}, out).ok());
  EXPECT_EQ(out[0], 0.25);
  EXPECT_TRUE(std::isnan(out[1]));
}

TEST(AbiController, ANullDereferenceInStepKillsTheProcessWithSigsegv) {
  const std::string probe = hiltwin::test::BesideTest(HILTWIN_TEST_CONTROLLER_PROBE);
  // The same probe on a good library steps normally, so the crash is the library's.
  const auto good = hiltwin::test::Run({probe, Lib("test_controller"), "0.001", "1,2,0.5,0.5"});
  EXPECT_EQ(good.exit_code, 0) << good.err;
  EXPECT_EQ(good.out, "step 1: duty_left=0.5 duty_right=1.5\n");
  // Under AddressSanitizer (the sanitizer stage) its own SIGSEGV handler would report and exit
  // 1: handle_segv=0 leaves the signal to kill, as in the program that ships.
  const char* asan = std::getenv("ASAN_OPTIONS");  // NOLINT(concurrency-mt-unsafe): one thread
  const std::string asan_options =
      "ASAN_OPTIONS=" + (asan != nullptr ? std::string(asan) + ":" : "") + "handle_segv=0";
  const auto crash = hiltwin::test::Run(
      {"env", asan_options, probe, Lib("null_dereference"), "0.001", "0,0,0,0"});
  EXPECT_FALSE(crash.status.exited) << crash.status.Describe() << "\n" << crash.err;
  EXPECT_EQ(crash.status.signal, SIGSEGV) << crash.status.Describe();
  EXPECT_EQ(crash.out, "");  // it died in its first step
}

}  // namespace
}  // namespace hiltwin::controller::test
