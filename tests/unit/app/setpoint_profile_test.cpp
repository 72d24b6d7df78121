#include "hiltwin/relbot/setpoint_profile.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>

#include "fakes/alloc_counter.h"

namespace hiltwin::app {
namespace {

std::string ErrorOf(const std::string& csv) {
  try {
    (void)ParseCsvSetpoints(csv, "sp.csv");
  } catch (const ProfileError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(ClosedLoopProfile, RestsMovesTwoAndAHalfMetresAndSettles) {
  const SetpointProfile profile = ClosedLoopProfile();
  EXPECT_EQ(profile.name(), "closedloop");
  EXPECT_EQ(profile.length_s(), kClosedLoopRestS + kClosedLoopMoveS + kClosedLoopSettleS);
  EXPECT_EQ(profile.length_s(), 12.0);
  EXPECT_EQ(profile.At(0.0).left_m, 0.0);
  EXPECT_EQ(profile.At(kClosedLoopRestS).right_m, 0.0);
  // Symmetric move: half way at half time, both wheels alike (straight ahead).
  const WheelPositions mid = profile.At(kClosedLoopRestS + 0.5 * kClosedLoopMoveS);
  EXPECT_NEAR(mid.left_m, 1.25, 1e-12);
  EXPECT_EQ(mid.left_m, mid.right_m);
  EXPECT_EQ(profile.At(kClosedLoopRestS + kClosedLoopMoveS).left_m, 2.5);
  EXPECT_EQ(profile.At(profile.length_s()).right_m, 2.5);
  EXPECT_EQ(profile.At(1000.0).left_m, 2.5);  // holds, does not repeat
}

TEST(ClosedLoopProfile, SpeedAndAccelerationAreSmoothAndWithinTheRobotsReach) {
  const SetpointProfile profile = ClosedLoopProfile();
  const double h = 1e-4;
  double max_speed = 0.0;
  double max_accel = 0.0;
  double max_jump = 0.0;
  double previous_accel = 0.0;
  for (double t = h; t < profile.length_s() - h; t += 1e-3) {
    const double p0 = profile.At(t - h).left_m;
    const double p1 = profile.At(t).left_m;
    const double p2 = profile.At(t + h).left_m;
    const double speed = (p2 - p0) / (2 * h);
    const double accel = (p2 - 2 * p1 + p0) / (h * h);
    max_speed = std::max(max_speed, std::abs(speed));
    max_accel = std::max(max_accel, std::abs(accel));
    if (t > 2 * h) max_jump = std::max(max_jump, std::abs(accel - previous_accel));
    previous_accel = accel;
  }
  EXPECT_NEAR(max_speed, 2.0 * 2.5 / kClosedLoopMoveS, 1e-4);  // 0.625 m/s
  EXPECT_LT(max_speed, 0.96 * 0.7);  // leaves the PID a duty margin above the 0.96 m/s top speed
  EXPECT_NEAR(max_accel, 2.0 * std::numbers::pi * 2.5 / 64.0, 2e-3);  // 0.245 m/s^2
  // Continuous acceleration: 1 ms apart it changes by at most ~jerk·1 ms (0.19 m/s^3), also at
  // the start and the end of the move, where a raised-cosine profile would jump by 0.19 m/s^2.
  EXPECT_LT(max_jump, 2e-3);
}

TEST(SetpointProfile, LinearSegmentsStepsAndHolding) {
  const SetpointProfile profile =
      ParseCsvSetpoints("time,left_m,right_m\n0,0,0\n1,0.1,-0.1\n1,0.2,0.3\n2,0.2,0.3\n", "sp.csv");
  EXPECT_EQ(profile.name(), "sp.csv");
  EXPECT_EQ(profile.length_s(), 2.0);
  EXPECT_NEAR(profile.At(0.5).left_m, 0.05, 1e-15);
  EXPECT_NEAR(profile.At(0.5).right_m, -0.05, 1e-15);
  EXPECT_EQ(profile.At(1.0).left_m, 0.2);  // right-continuous at the step
  EXPECT_EQ(profile.At(5.0).right_m, 0.3);
  EXPECT_EQ(profile.At(-1.0).left_m, 0.0);
  EXPECT_EQ(profile.At(std::numeric_limits<double>::quiet_NaN()).left_m, 0.0);
}

TEST(SetpointProfile, AcceptsTimeSAndAnyLetterCase) {
  EXPECT_NO_THROW((void)ParseCsvSetpoints("Time_s,LEFT_M,Right_m\n0,0,0\n1,1,1\n", "sp.csv"));
}

TEST(SetpointProfile, CsvErrorsNameFileLineAndColumn) {
  EXPECT_NE(ErrorOf("time,left,right\n0,0,0\n1,1,1\n")
                .find("sp.csv:1:2: expected the header 'time,left_m,right_m', found "
                      "'time,left,right'"),
            std::string::npos)
      << ErrorOf("time,left,right\n0,0,0\n1,1,1\n");
  EXPECT_NE(ErrorOf("0,0,0\n1,1,1\n").find("sp.csv:1:1: expected the header"), std::string::npos);
  EXPECT_NE(ErrorOf("time,left_m,right_m,x\n0,0,0,0\n1,1,1,1\n")
                .find("sp.csv:1:4: the header has more than the three columns"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf("time,left_m,right_m\n-1,0,0\n1,1,1\n").find("sp.csv:2:1: time -1 s is negative"),
      std::string::npos);
  EXPECT_NE(ErrorOf("time,left_m,right_m\n0,0,0\n2,1,1\n1,1,1\n").find("sp.csv:4:1:"),
            std::string::npos)
      << ErrorOf("time,left_m,right_m\n0,0,0\n2,1,1\n1,1,1\n");
  EXPECT_NE(ErrorOf("time,left_m,right_m\n0,0,0\n1,abc,1\n").find("sp.csv:3:2:"), std::string::npos)
      << ErrorOf("time,left_m,right_m\n0,0,0\n1,abc,1\n");
  EXPECT_NE(ErrorOf("time,left_m,right_m\n0,0,0\n0,1,1\n").find("the last time is 0 s"),
            std::string::npos);
}

TEST(SetpointProfile, KnotsAreValidated) {
  EXPECT_THROW((void)SetpointProfile::FromKnots("k", {{0.0, {0, 0}}}), ProfileError);
  EXPECT_THROW((void)SetpointProfile::FromKnots(
                   "k", {{0.0, {0, 0}}, {1.0, {0, 0}}, {1.0, {1, 0}}, {1.0, {2, 0}}}),
               ProfileError);
  EXPECT_THROW((void)SetpointProfile::FromKnots(
                   "k", {{0.0, {0, 0}}, {1.0, {std::numeric_limits<double>::infinity(), 0}}}),
               ProfileError);
}

TEST(SetpointProfile, LoadsFilesAndBuiltInsByName) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("hiltwin_sp_" + std::to_string(getpid()) + ".csv");
  std::ofstream(path) << "time,left_m,right_m\n0,0,0\n3,0.3,0.3\n";
  EXPECT_EQ(LoadSetpointProfile(path.string()).length_s(), 3.0);
  std::filesystem::remove(path);
  EXPECT_EQ(LoadSetpointProfile("closedloop").name(), "closedloop");
  try {
    (void)LoadSetpointProfile("closed-loop");
    FAIL() << "no error";
  } catch (const ProfileError& error) {
    EXPECT_NE(std::string(error.what()).find("neither a built-in profile (closedloop)"),
              std::string::npos)
        << error.what();
  }
}

TEST(SetpointProfile, EvaluationAllocatesNothing) {
  const SetpointProfile profile = ClosedLoopProfile();
  double sum = 0.0;
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount count;
    for (int k = 0; k < 20'000; ++k) sum += profile.At(k * 1e-3).left_m;
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0U);
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace hiltwin::app
