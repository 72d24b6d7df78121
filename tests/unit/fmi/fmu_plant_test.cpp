// FmuPlant with the good test FMUs: what Info says, the analytic answers through the plant
// interface, start/reset/finish, the fault path, no allocation in Step, the unpack folder.
#include "hiltwin/fmi/fmu_plant.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fakes/alloc_counter.h"
#include "hiltwin/plant/plant_map.h"
#include "test_fmus.h"

namespace hiltwin::fmi {
namespace {

using test::LagY;
using test::MsdResponse;
using test::TestFmu;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Pair;

constexpr double kStepS = 1e-3;
constexpr int kTwoSecondsSteps = 2000;

TEST(FmuInfo, LagPortsUnitsStepAndDetails) {
  const auto plant = OpenFmu(TestFmu("lag"));
  const plant::PlantInfo& info = plant->Info();
  EXPECT_EQ(info.name, "fmu:" + TestFmu("lag").string());
  EXPECT_EQ(info.kind, "FMI 2.0 co-simulation");
  ASSERT_EQ(info.inputs.size(), 1U);
  EXPECT_EQ(info.inputs[0].name, "u");
  EXPECT_EQ(info.inputs[0].unit, "1");
  ASSERT_EQ(info.outputs.size(), 1U);
  EXPECT_EQ(info.outputs[0].name, "y");
  EXPECT_EQ(info.outputs[0].unit, "rad");
  EXPECT_DOUBLE_EQ(info.model_step_s, 0.001);
  EXPECT_FALSE(info.step_is_fixed);
  EXPECT_THAT(info.details, ::testing::ElementsAre(
                                Pair("modelName", "FirstOrderLag"), Pair("modelIdentifier", "lag"),
                                Pair("generationTool", "hiltwin tests/fmus"),
                                Pair("guid", "{hiltwin-test-fmu-lag}"), Pair("fmiVersion", "2.0")));
}

TEST(FmuInfo, MsdUnitsIncludingADeclaredType) {
  const auto plant = OpenFmu(TestFmu("msd"));
  const plant::PlantInfo& info = plant->Info();
  ASSERT_EQ(info.inputs.size(), 1U);
  EXPECT_EQ(info.inputs[0].name, "F");
  EXPECT_EQ(info.inputs[0].unit, "N");
  ASSERT_EQ(info.outputs.size(), 2U);
  EXPECT_EQ(info.outputs[0].name, "x");
  EXPECT_EQ(info.outputs[0].unit, "m");
  EXPECT_EQ(info.outputs[1].name, "v");
  EXPECT_EQ(info.outputs[1].unit, "m/s");  // from <TypeDefinitions> Velocity
  EXPECT_DOUBLE_EQ(info.model_step_s, 0.0005);
}

// Plant::ExplainNonPort says what follows the name: the map error quotes the name itself.
TEST(FmuInfo, ExplainNonPortNamesParametersAndNonRealVariables) {
  const auto plant = OpenFmu(TestFmu("lag"));
  EXPECT_EQ(plant->ExplainNonPort("K"),
            "is a parameter of lag.fmu (causality \"parameter\"); only inputs can be driven and "
            "outputs followed");
  EXPECT_EQ(plant->ExplainNonPort("steps"),
            "is an Integer variable of lag.fmu; only Real ports can be mapped");
  EXPECT_EQ(plant->ExplainNonPort("u"), "");  // a port: nothing to explain
  EXPECT_EQ(plant->ExplainNonPort("nope"), "");
}

// The map error names the variable once ('K' 'K' is a parameter ... before).
TEST(FmuInfo, AMapErrorNamesTheVariableOnce) {
  const auto plant = OpenFmu(TestFmu("lag"));
  try {
    static_cast<void>(plant::BindPlantMap(
        plant::ParsePlantMap("[[pwm]]\nchannel = 1\ninput = \"K\"\n", "map.toml"), *plant));
    FAIL() << "bound";
  } catch (const plant::PlantMapError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("map.toml:3:9: PWM channel input 'K' is a parameter of "
                                          "lag.fmu (causality \"parameter\")"),
                                ::testing::Not(HasSubstr("'K' 'K'"))));
  }
}

// The plant map's [inputs] constants are the inputs during initialisation: an FMU initialised
// in equilibrium with its input starts at K u and stays there (it started at 0 and rose).
TEST(FmuPlantStart, TheInitialInputsAreSetDuringInitialisation) {
  const auto plant = OpenFmu(TestFmu("lag_steady"));
  const std::array<double, 1> u{0.5};
  plant->SetInitialInputs(u);
  std::array<double, 1> y{-1.0};
  plant->Start(kStepS, y);
  EXPECT_EQ(y[0], test::kLagGain * 0.5);
  for (int k = 1; k <= 100; ++k) {
    ASSERT_TRUE(plant->Step(u, y).ok());
    ASSERT_NEAR(y[0], test::kLagGain * 0.5, 1e-12) << "step " << k;
  }
  plant->Reset(y);
  EXPECT_EQ(y[0], test::kLagGain * 0.5);
  const auto zero = OpenFmu(TestFmu("lag_steady"));  // without initial inputs: u = 0
  zero->Start(kStepS, y);
  EXPECT_EQ(y[0], 0.0);
}

TEST(FmuPlantOpen, CommandLineOptionsAnFmuCannotUseAreRefused) {
  plant::PlantOptions config;
  config.config_path = "params.toml";
  EXPECT_THAT([&] { (void)OpenFmuPlant(TestFmu("lag"), config); },
              ::testing::ThrowsMessage<plant::PlantError>(
                  AllOf(HasSubstr("--config params.toml"), HasSubstr("own parameters"))));
  plant::PlantOptions integrator;
  integrator.integrator = "rk4";
  EXPECT_THAT([&] { (void)OpenFmuPlant(TestFmu("lag"), integrator); },
              ::testing::ThrowsMessage<plant::PlantError>(
                  AllOf(HasSubstr("--integrator rk4"), HasSubstr("own solver"))));
  EXPECT_NE(OpenFmuPlant(TestFmu("lag"), {}), nullptr);
}

TEST(FmuPlantStep, LagMatchesTheAnalyticStepResponse) {
  const auto plant = OpenFmu(TestFmu("lag"));
  std::array<double, 1> y{-1.0};
  plant->Start(kStepS, y);
  EXPECT_EQ(y[0], 0.0);
  const std::array<double, 1> u{0.7};
  for (int k = 1; k <= 2500; ++k) {
    ASSERT_TRUE(plant->Step(u, y).ok()) << "step " << k;
    ASSERT_NEAR(y[0], LagY(u[0], k * kStepS), 1e-12) << "step " << k;
  }
  EXPECT_GT(y[0], 0.99 * 2.0 * 0.7);  // five time constants in: within 1 % of K u
}

TEST(FmuPlantStep, MsdFreeResponseFromItsInitialDisplacement) {
  const auto plant = OpenFmu(TestFmu("msd"));
  std::array<double, 2> y{};
  plant->Start(kStepS, y);
  EXPECT_EQ(y[0], test::kMsdX0M);  // y0 is the initial state, not zeros
  EXPECT_EQ(y[1], 0.0);
  const std::array<double, 1> no_force{0.0};
  for (int k = 1; k <= kTwoSecondsSteps; ++k) {
    ASSERT_TRUE(plant->Step(no_force, y).ok());
    const test::MsdState expected = MsdResponse(0.0, k * kStepS);
    ASSERT_NEAR(y[0], expected.x_m, 1e-10) << "step " << k;  // 1e-9 of the 0.1 m amplitude
    ASSERT_NEAR(y[1], expected.v_m_per_s, 1e-9) << "step " << k;
  }
}

TEST(FmuPlantStep, MsdStepForceResponse) {
  const auto plant = OpenFmu(TestFmu("msd"));
  std::array<double, 2> y{};
  plant->Start(kStepS, y);
  const std::array<double, 1> force{2.0};
  for (int k = 1; k <= 3000; ++k) {
    ASSERT_TRUE(plant->Step(force, y).ok());
    const test::MsdState expected = MsdResponse(force[0], k * kStepS);
    ASSERT_NEAR(y[0], expected.x_m, 1e-10) << "step " << k;
    ASSERT_NEAR(y[1], expected.v_m_per_s, 1e-9) << "step " << k;
  }
}

TEST(FmuPlantLifecycle, ResetReturnsToTheInitialStateAndRepeatsTheRun) {
  const auto plant = OpenFmu(TestFmu("msd"));
  std::array<double, 2> y0{};
  plant->Start(kStepS, y0);
  const std::array<double, 1> force{1.5};
  std::array<double, 2> y{};
  std::vector<double> first_run;
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(plant->Step(force, y).ok());
    first_run.push_back(y[0]);
  }
  std::array<double, 2> after_reset{-1.0, -1.0};
  plant->Reset(after_reset);
  EXPECT_EQ(after_reset, y0);
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(plant->Step(force, y).ok());
    ASSERT_EQ(y[0], first_run[static_cast<std::size_t>(k)]) << "step " << k;
  }
  // A second Start begins from scratch, at another step.
  plant->Start(2 * kStepS, after_reset);
  EXPECT_EQ(after_reset, y0);
  ASSERT_TRUE(plant->Step(force, y).ok());
  EXPECT_NEAR(y[0], MsdResponse(force[0], 2 * kStepS).x_m, 1e-12);
}

TEST(FmuPlantLifecycle, MisuseIsRefusedNotCrashed) {
  const auto plant = OpenFmu(TestFmu("lag"));
  std::array<double, 1> y{};
  const std::array<double, 1> u{};
  EXPECT_EQ(plant->Step(u, y).code, plant::PlantStatus::Code::kFault);  // before Start
  EXPECT_THROW(plant->Reset(y), plant::PlantError);
  EXPECT_THROW(plant->Start(0.0, y), plant::PlantError);
  std::array<double, 2> wrong{};
  EXPECT_THROW(plant->Start(kStepS, wrong), plant::PlantError);
  plant->Finish();
  plant->Finish();  // idempotent, and fine without Start
}

// Step's one "ready" flag stands for three conditions (an instance, initialised, no fault):
// each way of losing one refuses the step, and a wrong port count latches like an FMU fault.
TEST(FmuPlantLifecycle, StepIsRefusedAfterFinishAndAfterAWrongPortCount) {
  const auto plant = OpenFmu(TestFmu("msd"));
  std::array<double, 2> y{};
  const std::array<double, 1> force{1.0};
  plant->Start(kStepS, y);
  ASSERT_TRUE(plant->Step(force, y).ok());
  plant->Finish();
  EXPECT_EQ(plant->Step(force, y).code, plant::PlantStatus::Code::kFault);  // no instance
  plant->Start(kStepS, y);
  ASSERT_TRUE(plant->Step(force, y).ok());
  std::array<double, 1> too_few{};
  const plant::PlantStatus wrong = plant->Step(force, too_few);
  EXPECT_EQ(wrong.code, plant::PlantStatus::Code::kFault);
  EXPECT_STREQ(wrong.reason, "FMU plant stepped before Start or with the wrong port count");
  const std::array<double, 2> too_many{};
  EXPECT_EQ(plant->Step(too_many, y).code, plant::PlantStatus::Code::kFault);
  const plant::PlantStatus stays = plant->Step(force, y);  // right counts again: the fault stays
  EXPECT_EQ(stays.code, plant::PlantStatus::Code::kFault);
  EXPECT_STREQ(stays.reason, wrong.reason);
  plant->Reset(y);  // Reset clears it, from the initial state and model time 0
  ASSERT_TRUE(plant->Step(force, y).ok());
  EXPECT_NEAR(y[0], MsdResponse(force[0], kStepS).x_m, 1e-12);
}

TEST(FmuPlantFault, AnErrorStatusIsAFaultNamingTheCallAndItStays) {
  std::vector<std::string> lines;
  FmuOptions options;
  options.log_sink = [&lines](std::string_view line) { lines.emplace_back(line); };
  const auto plant = OpenFmu(TestFmu("lag_fail"), options);
  std::array<double, 1> y{};
  plant->Start(kStepS, y);
  const std::array<double, 1> u{1.0};
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(plant->Step(u, y).ok()) << "step " << k;
  }
  const plant::PlantStatus fault = plant->Step(u, y);
  EXPECT_EQ(fault.code, plant::PlantStatus::Code::kFault);
  EXPECT_STREQ(fault.reason, "fmi2DoStep returned fmi2Error");
  for (int k = 0; k < 3; ++k) {  // the FMU is not called again: the same fault comes back
    const plant::PlantStatus again = plant->Step(u, y);
    EXPECT_EQ(again.code, plant::PlantStatus::Code::kFault);
    EXPECT_STREQ(again.reason, "fmi2DoStep returned fmi2Error");
  }
  EXPECT_TRUE(lines.empty());  // the FMU's own message waits in the ring until a drain
  plant->Finish();
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_THAT(lines[0], HasSubstr("[fmi2Error] logStatusError: failing on purpose at t = 0.1 s"));
  // fmi2Reset is allowed after fmi2Error: the plant runs again.
  plant->Start(kStepS, y);
  EXPECT_TRUE(plant->Step(u, y).ok());
}

TEST(FmuPlantRealTime, StepAllocatesNothing) {
  const auto plant = OpenFmu(TestFmu("msd"));
  std::array<double, 2> y{};
  plant->Start(kStepS, y);
  std::array<double, 1> force{0.0};
  bool all_ok = true;
  std::uint64_t allocations = 0;
  {
    const hiltwin::test::ScopedAllocationCount counter;
    for (int k = 0; k < 10000; ++k) {
      force[0] = (k / 1000) % 2 == 0 ? 1.0 : -1.0;
      all_ok = plant->Step(force, y).ok() && all_ok;
    }
    allocations = counter.count();
  }
  EXPECT_TRUE(all_ok);
  EXPECT_EQ(allocations, 0U) << "malloc counted: " << hiltwin::test::MallocIsCounted();
}

TEST(FmuPlantUnpack, PrivateFolderWhileOpenGoneAfterDestruction) {
  auto plant = OpenFmu(TestFmu("lag"));
  const std::filesystem::path dir = plant->unpack_dir();
  ASSERT_TRUE(std::filesystem::is_directory(dir));
  EXPECT_TRUE(std::filesystem::exists(dir / "modelDescription.xml"));
  EXPECT_TRUE(std::filesystem::exists(dir / "binaries" / HILTWIN_FMU_PLATFORM / "lag.so"));
  struct stat info {};
  ASSERT_EQ(stat(dir.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777U, 0700U);
  std::array<double, 1> y{};
  plant->Start(kStepS, y);
  plant.reset();
  EXPECT_FALSE(std::filesystem::exists(dir));
}

}  // namespace
}  // namespace hiltwin::fmi
