// The FMU's logger: messages logged from inside fmi2DoStep wait in the ring and come out at a
// drain (never during Step); none is lost below the ring's capacity, and above it the drop
// count is exact and reported.
#include "fmu_log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "hiltwin/fmi/fmu_plant.h"
#include "test_fmus.h"

namespace hiltwin::fmi {
namespace {

using test::TestFmu;
using ::testing::EndsWith;
using ::testing::HasSubstr;

constexpr std::size_t kRingMessages = 64;

class FmuLogging : public ::testing::Test {
 protected:
  void SetUp() override {
    FmuOptions options;
    options.log_capacity_messages = kRingMessages;
    options.log_sink = [this](std::string_view line) { lines_.emplace_back(line); };
    plant_ = OpenFmu(TestFmu("lag_log"), options);
    plant_->Start(1e-3, y_);
    lines_.clear();
  }
  void Steps(int count) {
    const std::array<double, 1> u{1.0};
    for (int k = 0; k < count; ++k) {
      ASSERT_TRUE(plant_->Step(u, y_).ok());
    }
  }

  std::unique_ptr<FmuPlant> plant_;
  std::array<double, 1> y_{};
  std::vector<std::string> lines_;
};

TEST_F(FmuLogging, MessagesComeOutAtTheDrainNoneLostBelowCapacity) {
  Steps(static_cast<int>(kRingMessages));
  EXPECT_TRUE(lines_.empty());  // nothing written from the loop
  EXPECT_EQ(plant_->DrainLog(), kRingMessages);
  ASSERT_EQ(lines_.size(), kRingMessages);
  EXPECT_EQ(lines_.front(), "fmu lag_log [fmi2OK] logEvents: step at t = 0.000 s");
  EXPECT_EQ(lines_.back(), "fmu lag_log [fmi2OK] logEvents: step at t = 0.063 s");
  EXPECT_EQ(plant_->log_messages_dropped(), 0U);
  Steps(10);  // the ring is reusable after a drain
  EXPECT_EQ(plant_->DrainLog(), 10U);
  EXPECT_EQ(lines_.back(), "fmu lag_log [fmi2OK] logEvents: step at t = 0.073 s");
}

TEST_F(FmuLogging, AboveCapacityTheDropCountIsExactAndReported) {
  Steps(static_cast<int>(kRingMessages) + 37);
  EXPECT_EQ(plant_->log_messages_dropped(), 37U);
  EXPECT_EQ(plant_->DrainLog(), kRingMessages);
  ASSERT_EQ(lines_.size(), kRingMessages + 1);
  EXPECT_THAT(lines_.back(), HasSubstr("fmu lag_log: 37 log messages dropped (the ring holds 64"));
  // The oldest messages are kept: the ring refuses new ones when full.
  EXPECT_EQ(lines_[kRingMessages - 1], "fmu lag_log [fmi2OK] logEvents: step at t = 0.063 s");
  Steps(5);
  plant_->Finish();  // drains what is left, and reports no new drops
  EXPECT_EQ(lines_.size(), kRingMessages + 1 + 5);
  EXPECT_EQ(plant_->log_messages_dropped(), 37U);
}

TEST(FmuLogRing, LongMessagesAreCutNotOverflowed) {
  std::vector<std::string> lines;
  FmuLog log("inst", 2, [&lines](std::string_view line) { lines.emplace_back(line); });
  const std::string long_text(2000, 'x');
  FmuLog::Callback(&log, "inst", fmi2Warning, "cat", "%s", long_text.c_str());
  FmuLog::Callback(&log, "inst", fmi2Error, nullptr, "value %d", 42);
  FmuLog::Callback(&log, "inst", fmi2OK, "cat", "dropped");
  EXPECT_EQ(log.Drain(), 2U);
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_THAT(lines[0], ::testing::StartsWith("fmu inst [fmi2Warning] cat: xxx"));
  EXPECT_THAT(lines[0], EndsWith("x..."));
  EXPECT_EQ(lines[0].size(),
            std::string("fmu inst [fmi2Warning] cat: ").size() + FmuLog::kTextBytes - 1);
  EXPECT_EQ(lines[1], "fmu inst [fmi2Error]: value 42");
  EXPECT_THAT(lines[2], HasSubstr("1 log messages dropped"));
}

}  // namespace
}  // namespace hiltwin::fmi
