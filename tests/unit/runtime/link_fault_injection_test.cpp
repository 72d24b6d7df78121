#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/runtime/link_faulting_task.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace hiltwin::runtime {
namespace {

using io::Describe;
using io::LinkFaultInjection;
using io::LinkFaultSchedule;
using io::ParseLinkFaultInjection;
using Kind = LinkFaultInjection::Kind;

TEST(LinkFaultInjection, ParsesKindsAndDefaults) {
  const LinkFaultInjection drop = ParseLinkFaultInjection("drop-answer,at=4000,count=3");
  EXPECT_EQ(drop.kind, Kind::kDropAnswer);
  EXPECT_EQ(drop.first_exchange, 4000U);
  EXPECT_EQ(drop.count, 3U);
  EXPECT_FALSE(drop.until_end);
  const LinkFaultInjection one = ParseLinkFaultInjection("corrupt-request,at=7");
  EXPECT_EQ(one.kind, Kind::kCorruptRequest);
  EXPECT_EQ(one.count, 1U);
  const LinkFaultInjection stuck = ParseLinkFaultInjection("stuck-encoder,at=10");
  EXPECT_TRUE(stuck.until_end);
  EXPECT_FALSE(ParseLinkFaultInjection("stuck-encoder,at=10,count=5").until_end);
  EXPECT_EQ(Describe(drop), "drop-answer,at=4000,count=3");
  EXPECT_EQ(Describe(stuck), "stuck-encoder,at=10");
  EXPECT_EQ(ParseLinkFaultInjection("delay-answer,count=2,at=1").kind, Kind::kDelayAnswer);
  EXPECT_EQ(ParseLinkFaultInjection("corrupt-answer,at=0").kind, Kind::kCorruptAnswer);
}

TEST(LinkFaultInjection, RejectsMalformedSpecsWithTheAcceptedForm) {
  for (const char* bad : {"", "at=3", "drop-answer", "drop-answer,at=x", "flip,at=3",
                          "drop-answer,at=3,count=0", "drop-answer,at=3,count=100000001",
                          "drop-answer,at=-1", "drop-answer,at=3,foo=1", "drop-answer,at=3,,",
                          "drop-answer,3"}) {
    try {
      static_cast<void>(ParseLinkFaultInjection(bad));
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(std::string("'") + bad + "'"), std::string::npos) << what;
      EXPECT_NE(what.find("KIND,at=K[,count=N]"), std::string::npos) << what;
    }
  }
}

TEST(LinkFaultSchedule, RefusesAFaultOutsideTheRunAndTooMany) {
  LinkFaultSchedule schedule;
  schedule.Add(ParseLinkFaultInjection("drop-answer,at=99"));
  EXPECT_NO_THROW(schedule.CheckFiresWithin(100));
  EXPECT_NO_THROW(schedule.CheckFiresWithin(0));  // no end: any exchange may come
  try {
    schedule.CheckFiresWithin(99);
    ADD_FAILURE() << "accepted a fault at exchange 99 of 0..98";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("0 to 98"), std::string::npos) << e.what();
  }
  for (std::size_t i = 1; i < LinkFaultSchedule::kMaxInjections; ++i)
    schedule.Add(ParseLinkFaultInjection("corrupt-answer,at=1"));
  EXPECT_THROW(schedule.Add(ParseLinkFaultInjection("corrupt-answer,at=1")), std::length_error);
}

/// Records the board's fault hooks as each exchange sees them.
class RecordingTask final : public RunTask {
 public:
  explicit RecordingTask(io::EmulatedFpga& board) : board_(board) {}
  io::ExchangeStatus Exchange(bool /*live_outputs*/) noexcept override {
    seen.push_back(board_.faults());
    return {};
  }
  StepStatus Step(const scheduler::CycleContext& /*context*/) noexcept override { return {}; }
  [[nodiscard]] std::vector<std::string> LogColumns() const override { return {"x"}; }
  [[nodiscard]] double LogTimeS() const noexcept override { return 1.5; }
  void FillLogRow(std::span<double> values) const noexcept override { values[0] = 2.5; }
  std::vector<io::FaultInjection> seen;

 private:
  io::EmulatedFpga& board_;
};

TEST(LinkFaultingTask, ArmsTheBoardAtTheChosenExchangesAndForwardsTheRest) {
  io::EmulatedFpga board(io::Image::kIcoboardInverse);
  RecordingTask inner(board);
  LinkFaultSchedule schedule;
  schedule.Add(ParseLinkFaultInjection("drop-answer,at=2,count=3"));
  schedule.Add(ParseLinkFaultInjection("corrupt-request,at=4"));
  schedule.Add(ParseLinkFaultInjection("stuck-encoder,at=3,count=2"));
  schedule.Add(ParseLinkFaultInjection("stuck-encoder,at=7"));
  LinkFaultingTask task(inner, board, schedule);
  for (int i = 0; i < 9; ++i) static_cast<void>(task.Exchange(true));
  ASSERT_EQ(inner.seen.size(), 9U);
  EXPECT_EQ(task.exchanges(), 9U);
  // The recording task does not consume the board's counters, so they stay as armed.
  EXPECT_EQ(inner.seen[1].drop_answers, 0U);
  EXPECT_EQ(inner.seen[2].drop_answers, 3U);
  EXPECT_EQ(inner.seen[3].corrupt_requests, 0U);
  EXPECT_EQ(inner.seen[4].corrupt_requests, 1U);
  const std::vector<bool> stuck_expected = {false, false, false, true, true, false, false, true,
                                            true};
  for (std::size_t i = 0; i < stuck_expected.size(); ++i)
    EXPECT_EQ(inner.seen[i].stick_encoder, stuck_expected[i]) << "exchange " << i;
  EXPECT_EQ(task.LogColumns(), std::vector<std::string>{"x"});
  EXPECT_EQ(task.LogTimeS(), 1.5);
  double row[1] = {0.0};
  task.FillLogRow(row);
  EXPECT_EQ(row[0], 2.5);
}

}  // namespace
}  // namespace hiltwin::runtime
