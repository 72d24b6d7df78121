#include "hiltwin/kernel_glue/stop_signal.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <thread>

namespace hiltwin::kernel_glue {
namespace {

bool HandlerIsDefault(int signal_number) {
  struct sigaction current {};
  sigaction(signal_number, nullptr, &current);
  return current.sa_handler == SIG_DFL;
}

class StopSignal : public ::testing::Test {
 protected:
  void SetUp() override {
    InstallStopSignalHandlers();
    ResetStopRequest();
  }
  // Leave the test process as we found it: Ctrl-C must still end the test run.
  void TearDown() override {
    ResetStopRequest();
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::signal(SIGHUP, SIG_DFL);
  }
};

TEST_F(StopSignal, NothingRequestedAtFirst) {
  EXPECT_FALSE(StopRequested());
  EXPECT_EQ(::hiltwin::kernel_glue::StopSignal(), 0);
}

TEST_F(StopSignal, SigintSetsTheFlagAndNamesTheSignal) {
  ASSERT_EQ(std::raise(SIGINT), 0);
  EXPECT_TRUE(StopRequested());
  EXPECT_EQ(::hiltwin::kernel_glue::StopSignal(), SIGINT);
}

TEST_F(StopSignal, SigtermSetsTheFlagAndNamesTheSignal) {
  ASSERT_EQ(std::raise(SIGTERM), 0);
  EXPECT_TRUE(StopRequested());
  EXPECT_EQ(::hiltwin::kernel_glue::StopSignal(), SIGTERM);
}

// A closed terminal or a dropped SSH session (issue 34): a stop like SIGTERM, not a kill.
TEST_F(StopSignal, SighupSetsTheFlagAndNamesTheSignal) {
  ASSERT_EQ(std::raise(SIGHUP), 0);
  EXPECT_TRUE(StopRequested());
  EXPECT_EQ(::hiltwin::kernel_glue::StopSignal(), SIGHUP);
  EXPECT_STREQ(StopSignalName(::hiltwin::kernel_glue::StopSignal()), "SIGHUP");
}

TEST_F(StopSignal, EveryStopSignalHasItsName) {
  EXPECT_STREQ(StopSignalName(SIGINT), "SIGINT");
  EXPECT_STREQ(StopSignalName(SIGTERM), "SIGTERM");
  EXPECT_STREQ(StopSignalName(-1), "a stop request");
  EXPECT_STREQ(StopSignalName(0), "no stop signal");
}

TEST_F(StopSignal, TheFirstCauseIsKept) {
  ASSERT_EQ(std::raise(SIGTERM), 0);
  RequestStop();
  EXPECT_EQ(::hiltwin::kernel_glue::StopSignal(), SIGTERM);
}

TEST_F(StopSignal, RequestStopFromCode) {
  RequestStop();
  EXPECT_TRUE(StopRequested());
  EXPECT_EQ(::hiltwin::kernel_glue::StopSignal(), -1);
}

TEST_F(StopSignal, FlagRaisedOnAnotherThreadIsSeenHere) {
  std::thread other([] { std::raise(SIGINT); });
  other.join();
  EXPECT_TRUE(StopRequested());
}

TEST_F(StopSignal, FirstSignalDisarmsItsHandlerAndResetRearmsIt) {
  EXPECT_FALSE(HandlerIsDefault(SIGINT));
  ASSERT_EQ(std::raise(SIGINT), 0);
  EXPECT_TRUE(HandlerIsDefault(SIGINT));    // a second Ctrl-C now kills
  EXPECT_FALSE(HandlerIsDefault(SIGTERM));  // the other signal is still a stop request
  ResetStopRequest();
  EXPECT_FALSE(StopRequested());
  EXPECT_FALSE(HandlerIsDefault(SIGINT));
  ASSERT_EQ(std::raise(SIGINT), 0);
  EXPECT_TRUE(StopRequested());
}

using StopSignalDeathTest = StopSignal;

TEST(PauseSignal, Sigusr1PausesSigusr2ResumesAndTheLatestRequestWins) {
  InstallPauseSignalHandlers();
  EXPECT_EQ(TakePauseRequest(), PauseRequest::kNone);
  ASSERT_EQ(raise(SIGUSR1), 0);
  EXPECT_EQ(TakePauseRequest(), PauseRequest::kPause);
  EXPECT_EQ(TakePauseRequest(), PauseRequest::kNone);  // taken: cleared
  ASSERT_EQ(raise(SIGUSR1), 0);
  ASSERT_EQ(raise(SIGUSR2), 0);
  EXPECT_EQ(TakePauseRequest(), PauseRequest::kResume);
  EXPECT_FALSE(StopRequested());  // pausing is not stopping
}

TEST_F(StopSignalDeathTest, SecondSigintKillsAStuckProgram) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        InstallStopSignalHandlers();
        std::raise(SIGINT);
        if (!StopRequested()) _exit(3);  // the first one must only ask
        std::raise(SIGINT);
        _exit(0);  // not reached: the default action terminates
      },
      ::testing::KilledBySignal(SIGINT), "");
}

}  // namespace
}  // namespace hiltwin::kernel_glue
