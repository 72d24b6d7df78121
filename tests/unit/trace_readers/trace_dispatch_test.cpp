// ReadTrace chooses the reader by what the path is, and ReadCtfTrace's refusals that need no
// LTTng session: a folder without any CTF metadata, a path that is not a folder.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "hiltwin/traces/trace_readers.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class TraceDispatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_trace_dispatch_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  template <typename Read>
  static std::string ErrorOf(Read read, const std::string& path) {
    try {
      static_cast<void>(read(path));
    } catch (const TraceReadError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(TraceDispatchTest, AFolderIsReadAsAnLttngTrace) {
  // Empty: the CTF reader's own refusal proves ReadTrace chose it.
  const std::string path = dir_.string();
  EXPECT_EQ(ErrorOf([](const std::string& p) { return ReadTrace(p); }, path),
            "no LTTng trace in " + path +
                ": no CTF `metadata` file below it; record one with `hiltwin trace --output DIR` "
                "or pass a timing log file");
}

TEST_F(TraceDispatchTest, AFolderWithOtherFilesButNoMetadataHasNoTrace) {
  fs::create_directories(dir_ / "ust" / "uid" / "0" / "64-bit");
  std::ofstream(dir_ / "ust" / "uid" / "0" / "64-bit" / "channel0_0") << "not a stream";
  std::ofstream(dir_ / "kernel_events.csv") << "time_ns\n";
  EXPECT_THAT(ErrorOf([](const std::string& p) { return ReadCtfTrace(p); }, dir_.string()),
              HasSubstr("no CTF `metadata` file below it"));
}

TEST_F(TraceDispatchTest, AFileIsReadAsATimingLog) {
  const std::string path = (dir_ / "timing.csv").string();
  std::ofstream(path) << "# hiltwin timing log 1\n# period_ns=1000\n# deadline_ns=1000\n"
                         "# planned_cycles=0\n"
                         "time_s,k,release_ns,wake_ns,start_ns,end_ns,io_ns,skipped,missed,judged\n"
                         "0,0,0,1,2,3,0,0,0,1\n";
  const TimingTrace trace = ReadTrace(path);
  EXPECT_EQ(trace.source, TraceSource::kTimingLog);
  EXPECT_EQ(trace.cycles.size(), 1U);
  EXPECT_TRUE(trace.rules.empty());
  EXPECT_STREQ(ToString(trace.source), "timing_log");
  EXPECT_STREQ(ToString(TraceSource::kLttng), "lttng");
}

TEST_F(TraceDispatchTest, AMissingPathSaysWhatIsAccepted) {
  const std::string path = (dir_ / "nowhere").string();
  EXPECT_EQ(ErrorOf([](const std::string& p) { return ReadTrace(p); }, path),
            path +
                " does not exist; pass an LTTng trace folder (`hiltwin trace --output DIR`) "
                "or a timing log file (`hiltwin run --timing-log FILE`)");
}

TEST_F(TraceDispatchTest, ReadCtfTraceRefusesAFile) {
  const std::string path = (dir_ / "file").string();
  std::ofstream(path) << "x";
  EXPECT_THAT(ErrorOf([](const std::string& p) { return ReadCtfTrace(p); }, path),
              HasSubstr("no LTTng trace in " + path + ": it is not a folder"));
}

}  // namespace
}  // namespace hiltwin::analysis
