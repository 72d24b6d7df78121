// The twin as its controller sees it through the board. Periods and speeds are powers of two,
// so every expected error below is exact in binary floating point.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "hiltwin/tuning/tuning.h"

namespace hiltwin::analysis {
namespace {

constexpr double kTwinPeriodS = 1.0 / 4096.0;        // T
constexpr double kControllerPeriodS = 1.0 / 1024.0;  // 4 T
constexpr double kSpeedMps = 0.5;                    // v
constexpr std::size_t kSamples = 100;

// Exchange k at k T + delay_s; cycle k's step computes v (k + 1 + lead) T + offset_m, the
// right wheel the mirror offset.
TwinTrajectory Ramp(double delay_s, int lead_cycles, double offset_m) {
  TwinTrajectory twin;
  twin.period_s = kTwinPeriodS;
  const std::size_t cycles = 4 * kSamples + 2;
  for (std::size_t k = 0; k < cycles; ++k) {
    const double position_m =
        kSpeedMps * static_cast<double>(static_cast<int>(k) + 1 + lead_cycles) * kTwinPeriodS;
    twin.exchange_time_s.push_back(static_cast<double>(k) * kTwinPeriodS + delay_s);
    twin.wheel_left_m.push_back(position_m + offset_m);
    twin.wheel_right_m.push_back(position_m - offset_m);
  }
  return twin;
}

// The reference ramp v t_j at t_j = j * 4 T.
ReferenceSamples RampReference() {
  ReferenceSamples reference;
  reference.controller_period_s = kControllerPeriodS;
  for (std::size_t j = 1; j <= kSamples; ++j) {
    reference.wheel_left_m.push_back(kSpeedMps * static_cast<double>(j) * kControllerPeriodS);
    reference.wheel_right_m.push_back(kSpeedMps * static_cast<double>(j) * kControllerPeriodS);
  }
  return reference;
}

TEST(ControllerViewRmsError, IdealTwinLagsByOneStepOfTheRamp) {
  // At t_j = k T the board has just received target_k = v k T and still plays target_{k-1}:
  // the controller reads v (t_j - T), one step of the ramp behind, so the RMS is exactly v T.
  EXPECT_EQ(ControllerViewRmsError(Ramp(0.0, 0, 0.0), RampReference()), kSpeedMps * kTwinPeriodS);
}

TEST(ControllerViewRmsError, TwinAheadByTheLagShowsOnlyItsOffset) {
  // One step ahead cancels the lag; +c on the left and -c on the right give an RMS of c.
  const double offset_m = 1.0 / 1024.0;
  EXPECT_EQ(ControllerViewRmsError(Ramp(0.0, 1, offset_m), RampReference()), offset_m);
}

TEST(ControllerViewRmsError, LateExchangeAddsTheRampOverTheDelay) {
  // Exchanges T/4 late: at t_j the latest exchange is k-1, three quarters played out, so the
  // controller reads v (k-1) T - v T/4 and the RMS grows from v T to v (T + T/4).
  const double delay_s = kTwinPeriodS / 4.0;
  const double ideal_m = ControllerViewRmsError(Ramp(0.0, 0, 0.0), RampReference());
  const double late_m = ControllerViewRmsError(Ramp(delay_s, 0, 0.0), RampReference());
  EXPECT_EQ(late_m, kSpeedMps * (kTwinPeriodS + delay_s));
  EXPECT_EQ(late_m - ideal_m, kSpeedMps * delay_s);
}

TEST(ControllerViewRmsError, BeforeTheFirstExchangeTheControllerSeesRest) {
  // The first exchange after t_1: the controller reads 0 there, against v t_1.
  TwinTrajectory twin = Ramp(0.0, 1, 0.0);
  for (double& t_s : twin.exchange_time_s) t_s += 1.5 * kControllerPeriodS;
  ReferenceSamples reference = RampReference();
  reference.wheel_left_m.resize(1);
  reference.wheel_right_m.resize(1);
  // Only t_1 is covered and the board is still at rest.
  EXPECT_EQ(ControllerViewRmsError(twin, reference), kSpeedMps * kControllerPeriodS);
}

TEST(ControllerViewRmsError, RefusesInputItCannotJudge) {
  const ReferenceSamples reference = RampReference();
  TwinTrajectory short_left = Ramp(0.0, 0, 0.0);
  short_left.wheel_left_m.pop_back();
  EXPECT_THROW((void)ControllerViewRmsError(short_left, reference), std::invalid_argument);
  ReferenceSamples uneven = reference;
  uneven.wheel_right_m.pop_back();
  EXPECT_THROW((void)ControllerViewRmsError(Ramp(0.0, 0, 0.0), uneven), std::invalid_argument);
  TwinTrajectory no_period = Ramp(0.0, 0, 0.0);
  no_period.period_s = 0.0;
  EXPECT_THROW((void)ControllerViewRmsError(no_period, reference), std::invalid_argument);
  ReferenceSamples no_controller_period = reference;
  no_controller_period.controller_period_s = -1.0;
  EXPECT_THROW((void)ControllerViewRmsError(Ramp(0.0, 0, 0.0), no_controller_period),
               std::invalid_argument);
  // Every exchange before t_1: no instant is covered.
  TwinTrajectory too_short = Ramp(0.0, 0, 0.0);
  too_short.exchange_time_s.resize(2);
  too_short.wheel_left_m.resize(2);
  too_short.wheel_right_m.resize(2);
  EXPECT_THROW((void)ControllerViewRmsError(too_short, reference), std::invalid_argument);
  EXPECT_THROW((void)ControllerViewRmsError(TwinTrajectory{kTwinPeriodS, {}, {}, {}}, reference),
               std::invalid_argument);
}

}  // namespace
}  // namespace hiltwin::analysis
