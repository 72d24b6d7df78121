// The 20-sim C++ class adapter (twentysim_plant.h) over the hand-written test model in
// plants/msd20sim: registration, the step check, the trajectory against the closed-form
// response, the first step, the finish time, Reset, no allocation, refused options.
#include "hiltwin/plant/twentysim_plant.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "LoopController.h"
#include "fakes/alloc_counter.h"
#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_registry.h"

namespace hiltwin::plant {
namespace {

using ::testing::HasSubstr;

// The model's documented parameters (plants/CMakeLists.txt, LoopController.cpp's header):
// restated here so the expected values come from the closed form, not from the code under test.
constexpr double kMassKg = 1.0;
constexpr double kSpringNPerM = 100.0;
constexpr double kDamperNsPerM = 4.0;
constexpr double kInitialPositionM = 0.05;
constexpr double kStepS = 0.001;
constexpr double kForceN = 10.0;

/// The exact response of m x'' + c x' + k x = F (F constant) from x(0) = x0, x'(0) = 0, for
/// the underdamped case: x = xs + A e^(-s t) (cos(wd t) + s/wd sin(wd t)), A = x0 - xs.
struct Exact {
  double position_m;
  double velocity_m_per_s;
};
Exact ExactResponse(double force_n, double t_s) {
  const double s = kDamperNsPerM / (2.0 * kMassKg);
  const double wn2 = kSpringNPerM / kMassKg;
  const double wd = std::sqrt(wn2 - s * s);
  const double xs = force_n / kSpringNPerM;
  const double a = kInitialPositionM - xs;
  const double decay = std::exp(-s * t_s);
  return {xs + a * decay * (std::cos(wd * t_s) + s / wd * std::sin(wd * t_s)),
          -a * wn2 / wd * decay * std::sin(wd * t_s)};
}

TwentySimPlantSpec MsdSpec(double finish_time_s) {
  TwentySimPlantSpec spec;
  spec.name = "msd_direct";
  spec.class_name = "LoopController";
  spec.inputs = {{"force_n", "N"}};
  spec.outputs = {{"position_m", "m"}, {"velocity_m_per_s", "m/s"}};
  spec.finish_time_s = finish_time_s;
  spec.integrator = "RungeKutta4";
  return spec;
}

std::unique_ptr<Plant> MakeRegistered(const PlantOptions& options = {}) {
  const PlantEntry* entry = FindPlant("msd20sim");
  if (entry == nullptr) return nullptr;
  return entry->make(options);
}

static_assert(TwentySimSubmodel<LoopController>, "the test model has 20-sim's class shape");
struct NotASubmodel {
  double m_step_size = 0.001;
  void Calculate(double* u, double* y);
};
static_assert(!TwentySimSubmodel<NotASubmodel>, "a class without Initialize/... is refused");

TEST(TwentySimPlant, RegistryFindsMsd20simWithItsPortsAndUnits) {
  const PlantEntry* entry = FindPlant("msd20sim");
  ASSERT_NE(entry, nullptr);
  EXPECT_FALSE(entry->description.empty());
  const std::unique_ptr<Plant> plant = entry->make({});
  ASSERT_NE(plant, nullptr);
  const PlantInfo& info = plant->Info();
  EXPECT_EQ(info.name, "msd20sim");
  EXPECT_EQ(info.kind, "20-sim C++ class");
  ASSERT_EQ(info.inputs.size(), 1U);
  EXPECT_EQ(info.inputs[0].name, "force_n");
  EXPECT_EQ(info.inputs[0].unit, "N");
  ASSERT_EQ(info.outputs.size(), 2U);
  EXPECT_EQ(info.outputs[0].name, "position_m");
  EXPECT_EQ(info.outputs[0].unit, "m");
  EXPECT_EQ(info.outputs[1].name, "velocity_m_per_s");
  EXPECT_EQ(info.outputs[1].unit, "m/s");
}

TEST(TwentySimPlant, InfoHasTheModelsFixedStepAndDetails) {
  const std::unique_ptr<Plant> plant = MakeRegistered();
  ASSERT_NE(plant, nullptr);
  const PlantInfo& info = plant->Info();
  EXPECT_EQ(info.model_step_s, 0.001);
  EXPECT_TRUE(info.step_is_fixed);
  std::string details;
  for (const auto& [key, value] : info.details)
    details.append(key).append("=").append(value).append("\n");
  EXPECT_THAT(details, HasSubstr("class=LoopController\n"));
  EXPECT_THAT(details, HasSubstr("integrator=RungeKutta4\n"));  // read from the header by CMake
  EXPECT_THAT(details, HasSubstr("step=0.001 s"));
  EXPECT_THAT(details, HasSubstr("finish time=0 s (endless)\n"));
}

TEST(TwentySimPlant, StartAtAnotherStepSaysWhichRateToUse) {
  const std::unique_ptr<Plant> plant = MakeRegistered();
  ASSERT_NE(plant, nullptr);
  std::array<double, 2> y0{};
  try {
    plant->Start(0.00025, y0);  // --rate 4000
    FAIL() << "a 4 kHz step was accepted by a model generated for 1 kHz";
  } catch (const PlantStepError& e) {  // a step error: the command line names --rate
    const std::string message = e.what();
    EXPECT_THAT(message, HasSubstr("--rate 4000 Hz gives a step of 0.00025 s"));
    EXPECT_THAT(message, HasSubstr("the 20-sim plant 'msd20sim' was generated for a step of "
                                   "0.001 s (m_step_size in LoopController.cpp)"));
    EXPECT_THAT(message, HasSubstr("run at --rate 1000,"));
    EXPECT_THAT(message, HasSubstr("regenerate the code with step size 0.00025 s"));
  }
  // A step off by more than the twin's 1 ns resolution is another step...
  EXPECT_THROW(plant->Start(kStepS + 2e-9, y0), PlantError);
  // ...one within it is the same step.
  EXPECT_NO_THROW(plant->Start(kStepS + 0.4e-9, y0));
}

/// A 20-sim-shaped submodel whose output is twice its input at once (direct feedthrough).
struct Doubler {
  double m_step_size = 0.001;
  void Initialize(double* u, double* y, double /*t*/) { y[0] = 2.0 * u[0]; }
  void Calculate(double* u, double* y) { y[0] = 2.0 * u[0]; }
  void Terminate(double* /*u*/, double* /*y*/) {}
  void SetFinishTime(double /*t*/) {}
  [[nodiscard]] bool IsFinished() const { return false; }
};

// Initialize gets the plant map's constant inputs, so an output that follows an input at once
// starts where the first step continues (it was computed with u = 0 and jumped in step 1).
TEST(TwentySimPlant, InitializeIsGivenTheInitialInputs) {
  TwentySimPlantSpec spec;
  spec.name = "doubler";
  spec.class_name = "Doubler";
  spec.inputs = {{"u", "1"}};
  spec.outputs = {{"y", "1"}};
  TwentySimPlant<Doubler> plant(spec);
  const std::array<double, 1> u0{0.25};
  plant.SetInitialInputs(u0);
  std::array<double, 1> y{};
  plant.Start(kStepS, y);
  EXPECT_EQ(y[0], 0.5);
  ASSERT_TRUE(plant.Step(u0, y).ok());
  EXPECT_EQ(y[0], 0.5);
  plant.Reset(y);
  EXPECT_EQ(y[0], 0.5);
}

TEST(TwentySimPlant, SuggestedRateMeetsTheStepAtWholeNanoseconds) {
  EXPECT_EQ(twentysim_detail::RateForStep(0.001), "1000");
  EXPECT_EQ(twentysim_detail::RateForStep(0.00025), "4000");
  EXPECT_EQ(twentysim_detail::RateForStep(1.0 / 3000.0), "3000");  // 333333 ns, within 1 ns
  EXPECT_EQ(twentysim_detail::RateForStep(0.0001234), "8103.73");  // 123400 ns
}

TEST(TwentySimPlant, FirstStepAdvancesTheModelByExactlyOneStep) {
  TwentySimPlant<LoopController> plant(MsdSpec(0.0));
  std::array<double, 2> y0{};
  plant.Start(kStepS, y0);
  EXPECT_EQ(y0[0], kInitialPositionM);
  EXPECT_EQ(y0[1], 0.0);
  EXPECT_EQ(plant.model().m_time, 0.0);
  EXPECT_EQ(plant.model().state, LoopController::mainrun);  // Start consumed "first call inits"

  const std::array<double, 1> u{kForceN};
  std::array<double, 2> y{};
  ASSERT_TRUE(plant.Step(u, y).ok());
  EXPECT_NEAR(plant.model().m_time, kStepS, 1e-15);
  const Exact exact = ExactResponse(kForceN, kStepS);
  // One RK4 step: local error O((wn h)^5) ~ 1e-10 relative, far below the change of a step
  // (2.5e-6 m in position, 5e-3 m/s in velocity). Had the step only initialised, y == y0.
  EXPECT_NEAR(y[0], exact.position_m, 1e-12);
  EXPECT_NEAR(y[1], exact.velocity_m_per_s, 1e-10);
  EXPECT_GT(y[0] - y0[0], 2e-6);
  EXPECT_GT(y[1], 4e-3);
}

TEST(TwentySimPlant, ConstantForceFollowsTheClosedFormStepResponse) {
  const std::unique_ptr<Plant> plant = MakeRegistered();
  ASSERT_NE(plant, nullptr);
  std::array<double, 2> y{};
  plant->Start(kStepS, y);
  const std::array<double, 1> u{kForceN};
  // RK4's global error at wn h = 0.01 over 3 s is ~1e-11 m here; 1e-9 m leaves room for
  // rounding yet fails RungeKutta2 (~2e-6 m) and Euler (~5e-4 m) outright.
  double worst_position_m = 0.0;
  double worst_velocity_m_per_s = 0.0;
  for (int k = 1; k <= 3000; ++k) {
    ASSERT_TRUE(plant->Step(u, y).ok()) << "step " << k;
    const Exact exact = ExactResponse(kForceN, k * kStepS);
    worst_position_m = std::max(worst_position_m, std::abs(y[0] - exact.position_m));
    worst_velocity_m_per_s =
        std::max(worst_velocity_m_per_s, std::abs(y[1] - exact.velocity_m_per_s));
  }
  EXPECT_LT(worst_position_m, 1e-9);
  EXPECT_LT(worst_velocity_m_per_s, 1e-8);
  EXPECT_NEAR(y[0], kForceN / kSpringNPerM, 1e-4);  // settled near F/k after 3 s (e^-6)
}

TEST(TwentySimPlant, FinishTimeStopsTheModelAndKeepsTheLastOutputs) {
  TwentySimPlant<LoopController> plant(MsdSpec(0.01));  // 10 steps of 1 ms
  std::array<double, 2> y{};
  plant.Start(kStepS, y);
  const std::array<double, 1> u{kForceN};
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(plant.Step(u, y).ok()) << "step " << k;
  const std::array<double, 2> last = y;
  const double last_time_s = plant.model().m_time;
  EXPECT_NEAR(last_time_s, 0.01, 1e-12);

  for (int k = 11; k <= 13; ++k) {
    std::array<double, 2> out{std::nan(""), std::nan("")};  // the adapter must write them
    const PlantStatus status = plant.Step(u, out);
    EXPECT_EQ(status.code, PlantStatus::Code::kFinished) << "step " << k;
    EXPECT_STREQ(status.reason, "the 20-sim model reached its finish time (m_finish_time)");
    EXPECT_EQ(out, last);
    EXPECT_EQ(plant.model().m_time, last_time_s);
  }
}

TEST(TwentySimPlant, ResetGivesBackTheInitialOutputsAndTheSameTrajectory) {
  const std::unique_ptr<Plant> plant = MakeRegistered();
  ASSERT_NE(plant, nullptr);
  std::array<double, 2> y0{};
  plant->Start(kStepS, y0);
  const std::array<double, 1> u{kForceN};
  std::vector<std::array<double, 2>> first;
  std::array<double, 2> y{};
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(plant->Step(u, y).ok());
    first.push_back(y);
  }
  std::array<double, 2> y0_again{1.0, 1.0};
  plant->Reset(y0_again);
  EXPECT_EQ(y0_again, y0);
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(plant->Step(u, y).ok());
    ASSERT_EQ(y, first[static_cast<std::size_t>(k)]) << "step " << k + 1;  // bit for bit
  }
}

TEST(TwentySimPlant, StepAllocatesNothing) {
  const std::unique_ptr<Plant> plant = MakeRegistered();
  ASSERT_NE(plant, nullptr);
  std::array<double, 2> y{};
  plant->Start(kStepS, y);
  const std::array<double, 1> u{kForceN};
  int not_ok = 0;
  std::uint64_t allocations = 0;
  {
    const test::ScopedAllocationCount count;  // operator new always; malloc when counted
    for (int k = 0; k < 10'000; ++k) not_ok += plant->Step(u, y).ok() ? 0 : 1;
    allocations = count.count();
  }
  EXPECT_EQ(not_ok, 0);
  EXPECT_EQ(allocations, 0U) << (test::MallocIsCounted() ? "malloc and new counted"
                                                         : "operator new counted");
}

TEST(TwentySimPlant, NonFiniteOutputIsAFault) {
  TwentySimPlant<LoopController> plant(MsdSpec(0.0));
  std::array<double, 2> y{};
  plant.Start(kStepS, y);
  const std::array<double, 1> u{std::numeric_limits<double>::infinity()};
  const PlantStatus status = plant.Step(u, y);
  EXPECT_EQ(status.code, PlantStatus::Code::kFault);
  EXPECT_STREQ(status.reason, "the 20-sim model's output became non-finite (NaN or Inf)");
}

TEST(TwentySimPlant, FinishIsIdempotentAndStepAfterItIsAFault) {
  TwentySimPlant<LoopController> plant(MsdSpec(0.0));
  std::array<double, 2> y{};
  plant.Finish();  // before Start: nothing to terminate
  EXPECT_THROW(plant.Reset(y), PlantError);
  plant.Start(kStepS, y);
  plant.Finish();
  plant.Finish();  // Terminate frees the integrator: twice would free it twice
  const std::array<double, 1> u{0.0};
  EXPECT_EQ(plant.Step(u, y).code, PlantStatus::Code::kFault);
  plant.Start(kStepS, y);  // a fresh submodel
  EXPECT_TRUE(plant.Step(u, y).ok());
}

TEST(TwentySimPlant, RefusesOptionsItCannotHonour) {
  for (const PlantOptions& options : {PlantOptions{"msd.toml", ""}, PlantOptions{"", "euler"}}) {
    try {
      static_cast<void>(MakeRegistered(options));
      FAIL() << "an option was silently ignored";
    } catch (const PlantError& e) {
      const std::string message = e.what();
      EXPECT_THAT(message, HasSubstr(options.config_path.empty() ? "--integrator euler"
                                                                 : "--config msd.toml"));
      EXPECT_THAT(message, HasSubstr("the 20-sim plant 'msd20sim' has its parameters and "
                                     "integrator compiled in: change them in 20-sim and "
                                     "regenerate, or edit m_step_size / myintegmethod in "
                                     "LoopController.cpp/.h as thesis appendix B §3 says"));
    }
  }
}

}  // namespace
}  // namespace hiltwin::plant
