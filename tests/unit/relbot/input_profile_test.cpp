#include "hiltwin/relbot/input_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <unistd.h>

#include "fakes/alloc_counter.h"

namespace hiltwin::app {
namespace {

std::string ProfileErrorOf(const std::string& csv) {
  try {
    (void)ParseCsvProfile(csv, "p.csv");
  } catch (const ProfileError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(OpenLoopProfile, LastsAbout36SecondsAndStaysWithinDutyRange) {
  const InputProfile profile = OpenLoopProfile();
  EXPECT_EQ(profile.name(), "openloop");
  EXPECT_DOUBLE_EQ(profile.period_s(), 36.0);
  double max_abs = 0.0;
  for (double t = 0.0; t < profile.period_s(); t += 1e-3) {
    const Duty d = profile.At(t);
    max_abs = std::max({max_abs, std::abs(d.left), std::abs(d.right)});
  }
  EXPECT_LE(max_abs, 1.0);
  EXPECT_EQ(max_abs, 1.0);  // it uses the full range
}

TEST(OpenLoopProfile, HasSuddenStepsAndGradualRampsOnBothWheels) {
  const InputProfile profile = OpenLoopProfile();
  const auto knots = profile.knots();
  int steps = 0;
  int ramps = 0;
  int turns = 0;
  for (std::size_t i = 1; i < knots.size(); ++i) {
    const bool changes = knots[i].duty.left != knots[i - 1].duty.left ||
                         knots[i].duty.right != knots[i - 1].duty.right;
    if (changes && knots[i].time_s == knots[i - 1].time_s) ++steps;
    if (changes && knots[i].time_s > knots[i - 1].time_s) ++ramps;
    if (knots[i].duty.left != knots[i].duty.right) ++turns;
  }
  EXPECT_GE(steps, 5);
  EXPECT_GE(ramps, 5);
  EXPECT_GE(turns, 3);
  EXPECT_EQ(knots.front().duty.left, 0.0);
  EXPECT_EQ(knots.back().duty.right, 0.0);  // repeats without a jump
}

TEST(InputProfile, InterpolatesLinearlyBetweenKnots) {
  const InputProfile profile = OpenLoopProfile();
  // Ramp 3 s -> 6 s from 0.4 to 1.0 on both wheels.
  EXPECT_NEAR(profile.At(4.5).left, 0.7, 1e-12);
  EXPECT_NEAR(profile.At(3.75).right, 0.55, 1e-12);
}

TEST(InputProfile, StepsAreRightContinuous) {
  const InputProfile profile = OpenLoopProfile();
  EXPECT_EQ(profile.At(8.0).left, -0.5);
  EXPECT_NEAR(profile.At(8.0 - 1e-9).left, 1.0, 1e-12);
  EXPECT_EQ(profile.At(1.0).left, 0.4);
  EXPECT_EQ(profile.At(0.999).left, 0.0);
}

TEST(InputProfile, RepeatsWithItsPeriod) {
  const InputProfile profile = OpenLoopProfile();
  for (double t = 0.0; t < 36.0; t += 0.137) {
    for (int repeat : {1, 2, 17}) {
      const Duty a = profile.At(t);
      const Duty b = profile.At(t + 36.0 * repeat);
      EXPECT_NEAR(a.left, b.left, 1e-9) << t << " + " << repeat << " periods";
      EXPECT_NEAR(a.right, b.right, 1e-9);
    }
  }
  // At a whole period the next repetition starts.
  EXPECT_EQ(profile.At(36.0).left, 0.0);
  EXPECT_NEAR(profile.At(36.0 + 4.5).left, 0.7, 1e-9);
}

TEST(InputProfile, OddTimesAreSafe) {
  const InputProfile profile = OpenLoopProfile();
  EXPECT_EQ(profile.At(std::numeric_limits<double>::quiet_NaN()).left, 0.0);
  EXPECT_EQ(profile.At(std::numeric_limits<double>::infinity()).right, 0.0);
  EXPECT_EQ(profile.At(-5.0).left, 0.0);
  const InputProfile late = InputProfile::FromKnots(
      "late", {{1.0, {0.5, -0.5}}, {2.0, {0.0, 0.0}}});
  EXPECT_EQ(late.At(0.5).left, 0.5);  // before the first knot its duty holds
}

TEST(InputProfile, EvaluationAllocatesNothing) {
  const InputProfile profile = OpenLoopProfile();
  double sum = 0.0;
  test::ScopedAllocationCount count;
  for (int k = 0; k < 100000; ++k) sum += profile.At(k * 1e-3).left;
  EXPECT_EQ(count.count(), 0U);
  EXPECT_NE(sum, 0.0);
}

// A cursor only saves the search: the duty is At(t)'s, bit for bit, whatever the order of
// the times and whatever the cursor held.
TEST(InputProfile, ACursorGivesTheSameDutyForwardBackwardAndAtRandom) {
  const InputProfile profile = OpenLoopProfile();
  const auto expect_same = [&profile](double t, std::size_t& cursor) {
    const Duty a = profile.At(t);
    const Duty b = profile.At(t, cursor);
    ASSERT_EQ(a.left, b.left) << t;
    ASSERT_EQ(a.right, b.right) << t;
  };
  std::size_t cursor = 0;
  for (int k = 0; k < 80'000; ++k) expect_same(k * 1e-3, cursor);  // forward over 2 periods
  for (int k = 80'000; k >= 0; k -= 7) expect_same(k * 1e-3, cursor);  // backward
  std::uint64_t seed = 12345;
  for (int k = 0; k < 20'000; ++k) {  // at random, steps and period ends included
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    const double t = static_cast<double>(seed >> 11) * 0x1p-53 * 100.0 - 1.0;
    expect_same(k % 5 == 0 ? std::round(t) : t, cursor);
  }
  const std::size_t n = profile.knots().size();
  for (const double t : {1.0, 8.0, 13.0, 34.5, 35.5, 36.0, 72.0, 0.0, -1.0, 1e9}) {
    for (std::size_t start : {std::size_t{0}, std::size_t{3}, n, n + 1,
                              std::numeric_limits<std::size_t>::max()}) {
      expect_same(t, start);
    }
  }
}

TEST(InputProfile, FromKnotsValidates) {
  EXPECT_THROW((void)InputProfile::FromKnots("x", {{0.0, {0.0, 0.0}}}), ProfileError);
  EXPECT_THROW((void)InputProfile::FromKnots("x", {{0.0, {0.0, 0.0}}, {0.0, {0.0, 0.0}}}),
               ProfileError);
  EXPECT_THROW((void)InputProfile::FromKnots("x", {{0.0, {1.5, 0.0}}, {1.0, {0.0, 0.0}}}),
               ProfileError);
  EXPECT_THROW((void)InputProfile::FromKnots("x", {{1.0, {0.0, 0.0}}, {0.5, {0.0, 0.0}}}),
               ProfileError);
  EXPECT_THROW(
      (void)InputProfile::FromKnots(
          "x", {{0.0, {0.0, 0.0}}, {1.0, {0.0, 0.0}}, {1.0, {0.5, 0.0}}, {1.0, {0.2, 0.0}}}),
      ProfileError);
  try {
    (void)InputProfile::FromKnots(
        "mine", {{0.0, {0.0, std::numeric_limits<double>::quiet_NaN()}}, {1.0, {0.0, 0.0}}});
    FAIL();
  } catch (const ProfileError& error) {
    EXPECT_NE(std::string(error.what()).find("'mine', knot 0"), std::string::npos);
  }
}

TEST(CsvProfile, ParsesWithCommentsBlankLinesCrLfAndSpaces) {
  const InputProfile profile = ParseCsvProfile(
      "# recorded on the bench\r\ntime_s, left, right\r\n\r\n0, 0, 0\r\n1.0,+0.5,-0.5\r\n"
      "1.0,1,-1\n  2 ,1e-1, -1.0e-1 \n",
      "p.csv");
  EXPECT_EQ(profile.name(), "p.csv");
  ASSERT_EQ(profile.knots().size(), 4U);
  EXPECT_DOUBLE_EQ(profile.period_s(), 2.0);
  EXPECT_NEAR(profile.At(0.5).left, 0.25, 1e-12);
  EXPECT_EQ(profile.At(1.0).right, -1.0);
  EXPECT_NEAR(profile.At(1.5).left, 0.55, 1e-12);
}

TEST(CsvProfile, AcceptsAUtf8ByteOrderMark) {
  const InputProfile profile =
      ParseCsvProfile("\xEF\xBB\xBFtime,left,right\n0,0.5,0.5\n1,0.5,0.5\n", "excel.csv");
  EXPECT_EQ(profile.At(0.5).left, 0.5);
}

struct BadCsv {
  const char* csv;
  const char* where;  // "p.csv:line:column:"
  const char* what;
};

// Columns count CSV fields from 1, as in every message of the shared reader (and of
// `hiltwin assess`), so leading spaces do not move them.
TEST(CsvProfile, ErrorsGiveLineColumnWhatAndWhatToDo) {
  const BadCsv cases[] = {
      {"", "p.csv:1:1:", "empty file"},
      {"t,l,r\n0,0,0\n1,0,0\n", "p.csv:1:1:", "expected the header 'time,left,right'"},
      {"0,0,0\n1,0,0\n", "p.csv:1:1:", "found a row of numbers"},
      {"time,left\n0,0\n1,0\n", "p.csv:1:3:", "expected the header"},
      {"time,left,right,x\n", "p.csv:1:4:", "more than the three columns"},
      {"time,left,right\n0,0,0\n1, abc,0\n", "p.csv:3:2:", "column 'left': 'abc' is not a number"},
      {"time,left,right\n0,0,0\n1,0,\n", "p.csv:3:3:", "column 'right': empty cell"},
      {"time,left,right\n0,nan,0\n1,0,0\n", "p.csv:2:2:", "not finite"},
      {"time,left,right\n0,0,0\n1,0,inf\n", "p.csv:3:3:", "not finite"},
      {"time,left,right\n0,0,0\n1,1e999,0\n", "p.csv:3:2:", "not finite"},
      {"time,left,right\n0,0,0\n1,0,1.5\n", "p.csv:3:3:", "right duty 1.5 is outside [-1, 1]"},
      {"time,left,right\n0,0,0\n2,0,0\n1,0,0\n", "p.csv:4:1:",
       "earlier than the previous row's 2 s (line 3)"},
      {"time,left,right\n0,0,0\n1,0,0\n1,0.5,0\n1,0.2,0\n", "p.csv:5:1:",
       "a third row (lines 3, 4 and 5)"},
      {"time,left,right\n0,0\n1,0,0\n", "p.csv:2:3:", "row has 2 cells but the header has 3"},
      {"time,left,right\n0,0,0,0\n1,0,0\n", "p.csv:2:4:", "row has 4 cells"},
      {"time,left,right\n-1,0,0\n1,0,0\n", "p.csv:2:1:", "negative"},
      {"time,left,right\n0,0,0\n", "p.csv:2:", "at least two rows for an input profile"},
      {"time,left,right\n0,0,0\n0,1,1\n", "p.csv:3:1:", "the last time is 0 s"},
  };
  for (const BadCsv& c : cases) {
    const std::string message = ProfileErrorOf(c.csv);
    EXPECT_EQ(message.rfind(c.where, 0), 0U) << c.csv << " -> " << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << c.csv << " -> " << message;
    EXPECT_NE(message.find("; "), std::string::npos) << "no advice in: " << message;
  }
}

TEST(CsvProfile, ReadsWhatTheAssessReaderReads) {
  // Semicolons or tabs (as a spreadsheet in a comma-decimal locale exports), quoted names.
  for (const char* csv : {"time;left;right\n0;0.5;0.5\n1;0.5;0.5\n",
                          "time\tleft\tright\n0\t0.5\t0.5\n1\t0.5\t0.5\n",
                          "\"time\",\"left\",\"right\"\n0,0.5,0.5\n1,0.5,0.5\n",
                          "TIME_S,Left,RIGHT\n0,0.5,0.5\n1,0.5,0.5\n"}) {
    const InputProfile profile = ParseCsvProfile(csv, "p.csv");
    EXPECT_DOUBLE_EQ(profile.period_s(), 1.0) << csv;
    EXPECT_EQ(profile.At(0.5).left, 0.5) << csv;
  }
}

TEST(CsvProfile, ReadsTheDutyColumnsOfAHiltwinLogAndIgnoresTheRest) {
  // An ECS open-loop log as RunSession writes it: time_s, the task's columns, timing columns.
  const char* log =
      "time_s,duty_left,duty_right,wheel_left_m,wheel_right_m,enc_left,enc_right,cycle,"
      "latency_us,compute_us,io_us,missed\n"
      "0,0,0,0,0,0,0,0,0,1.5,0.2,0\n"
      "0.001,0.25,-0.5,0,0,0,0,1,0,1.5,0.2,0\n"
      "0.002,0.5,-1,0.0001,-0.0001,1,-1,2,3.5,1.5,0.2,1\n";
  const InputProfile profile = ParseCsvProfile(log, "ecs.csv");
  ASSERT_EQ(profile.knots().size(), 3U);
  EXPECT_EQ(profile.knots()[1].duty.left, 0.25);
  EXPECT_EQ(profile.knots()[2].duty.right, -1.0);
  EXPECT_EQ(profile.period_s(), 0.002);
  // Any order of the columns, as long as both are named (the twin's log has them first).
  const InputProfile swapped =
      ParseCsvProfile("time,duty_right,x_m,duty_left\n0,0.1,5,0.2\n1,0.3,6,0.4\n", "t.csv");
  EXPECT_EQ(swapped.knots()[1].duty.left, 0.4);
  EXPECT_EQ(swapped.knots()[1].duty.right, 0.3);
}

TEST(CsvProfile, LogColumnsAreCheckedLikeProfileColumns) {
  const std::string bad_duty =
      ProfileErrorOf("time_s,wheel_left_m,duty_left,duty_right\n0,0,0,0\n1,0,1.5,0\n");
  EXPECT_EQ(bad_duty.rfind("p.csv:3:3: left duty 1.5 is outside [-1, 1]", 0), 0U) << bad_duty;
  // Only one of the two duty columns: not a log, and not a profile either.
  const std::string half = ProfileErrorOf("time_s,duty_left,wheel_left_m\n0,0,0\n1,0,0\n");
  EXPECT_EQ(half.rfind("p.csv:1:2: expected the header 'time,left,right' (or a hiltwin log", 0),
            0U)
      << half;
  const std::string no_time = ProfileErrorOf("cycle,duty_left,duty_right\n0,0,0\n1,0,0\n");
  EXPECT_EQ(no_time.rfind("p.csv:1:1:", 0), 0U) << no_time;
}

TEST(LoadInputProfile, BuiltInNameFileOrAClearError) {
  EXPECT_EQ(LoadInputProfile("openloop").name(), "openloop");
  ASSERT_EQ(BuiltinProfileNames().size(), 1U);
  EXPECT_EQ(BuiltinProfileNames()[0], "openloop");

  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("hiltwin_profile_test_" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream out(path);
    out << "time,left,right\n0,0.1,0.2\n3,0.3,0.4\n";
  }
  const InputProfile from_file = LoadInputProfile(path.string());
  EXPECT_EQ(from_file.name(), path.string());
  EXPECT_DOUBLE_EQ(from_file.period_s(), 3.0);
  {
    std::ofstream out(path);
    out << "time,left,right\n0,0.1,0.2\n3,0.3,x\n";
  }
  try {
    (void)LoadInputProfile(path.string());
    FAIL();
  } catch (const ProfileError& error) {
    EXPECT_EQ(std::string(error.what()).rfind(path.string() + ":3:3:", 0), 0U) << error.what();
  }
  std::filesystem::remove(path);

  try {
    (void)LoadInputProfile("openlop");
    FAIL();
  } catch (const ProfileError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'openlop'"), std::string::npos);
    EXPECT_NE(message.find("openloop"), std::string::npos);
  }
  EXPECT_THROW((void)LoadCsvProfile("/nonexistent/p.csv"), ProfileError);
}

// `run --input` on a file without line breaks (here /dev/zero, which never ends) fails at its
// first line once the CSV reader's line cap is passed, as a profile error naming the file.
TEST(LoadInputProfile, AFileWithoutLineBreaksIsRefusedAtItsFirstLine) {
  try {
    (void)LoadCsvProfile("/dev/zero");
    FAIL();
  } catch (const ProfileError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("/dev/zero:1: the line is longer than 65536 bytes", 0), 0U) << message;
  }
}

}  // namespace
}  // namespace hiltwin::app
