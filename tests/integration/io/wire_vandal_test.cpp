// Hostile shared memory (issue 16): `hiltwin run` (twin) and `hiltwin ecs` on a wire, and a
// third process (hiltwin_io_wire_vandal) writing garbage into their segment. Neither side may
// crash or act on the garbage: a side that read it stops on an I/O fault (exit 5) naming the
// corruption, with safe outputs and a complete log; a side that did not stops cleanly because
// its peer stopped. A seqlock torn for good is a loss, not a fault.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "fakes/wire_scratch.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

class WireVandalCli : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return scratch_.Path(name); }
  static std::string ReadFile(const std::string& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  // Long enough for two sanitizer-built processes on a busy 2-core machine to meet (the
  // sides' own wait for each other is 30 s).
  static bool WaitForText(const std::string& path, const std::string& text) {
    const auto end = Clock::now() + std::chrono::seconds(30);
    while (Clock::now() < end) {
      if (ReadFile(path).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  /// Both sides on this test's wire for up to 8 s, each with a report and a log; returns once
  /// both run, and lets them exchange for a moment.
  void StartPair() {
    for (const char* side : {"twin", "ecs"}) {
      const std::string command = std::string(side) == "twin" ? "run" : "ecs";
      const std::vector<std::string> args = {
          HILTWIN_BINARY, command, "--io", scratch_.Wire(), "--duration", "8", "--no-progress",
          "--report", Path(std::string(side) + ".json"), "--log", Path(std::string(side) + ".csv")};
      (std::string(side) == "twin" ? twin_ : ecs_).emplace(hiltwin::test::Spawn(args, Path(side)));
    }
    for (const char* side : {"twin", "ecs"}) {
      ASSERT_TRUE(WaitForText(Path(side) + ".err", "is up; starting"))
          << side << " never started; twin said:\n"
          << ReadFile(Path("twin.err")) << "ecs said:\n"
          << ReadFile(Path("ecs.err"));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  void Vandalise(const std::string& kind) {
    const auto r = hiltwin::test::Run({HILTWIN_WIRE_VANDAL, scratch_.WireName(), kind}, 10'000);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static hiltwin::kernel_glue::ExitStatus End(hiltwin::kernel_glue::Process& process) {
    return process.WaitFor(std::chrono::seconds(15)).value_or(hiltwin::kernel_glue::ExitStatus{});
  }
  nlohmann::json Report(const char* side) const {
    std::ifstream in(Path(std::string(side) + ".json"));
    return nlohmann::json::parse(in);
  }

  /// The side exited 5 on an I/O fault whose reason names `what` and the corrupted segment,
  /// with safe outputs and a log whose every row parses.
  void ExpectCorruptionFault(const char* side, const hiltwin::kernel_glue::ExitStatus& status,
                             const std::string& what) {
    SCOPED_TRACE(side);
    ASSERT_TRUE(status.exited) << status.Describe() << "\n" << ReadFile(Path(side) + ".err");
    EXPECT_EQ(status.code, 5) << ReadFile(Path(side) + ".err");
    const auto report = Report(side);
    EXPECT_EQ(report["stop_reason"], "io_fault");
    EXPECT_EQ(report["final_state"], "safe_stop");
    EXPECT_EQ(report["outputs_safe"], true);
    const std::string reason = report["fault"]["reason"].get<std::string>();
    EXPECT_NE(reason.find(what), std::string::npos) << reason;
    EXPECT_NE(reason.find("the segment is corrupted (another process writes into /dev/shm/"
                          "hiltwin-wire-" + scratch_.WireName() + ")"),
              std::string::npos)
        << reason;
    ExpectCompleteLog(side, report);
  }
  /// For garbage both sides read at their own pace: the side that read it first faults, and
  /// the other either read it too or saw its peer stop first (a race the sides' cycles decide).
  /// Returns whether this side faulted.
  bool ExpectCorruptionFaultOrPeerStopped(const char* side,
                                          const hiltwin::kernel_glue::ExitStatus& status,
                                          const std::string& what) {
    if (status.exited && status.code != 5 && Report(side)["stop_reason"] == "peer_stopped") {
      ExpectCleanEnd(side, status);
      return false;
    }
    ExpectCorruptionFault(side, status, what);
    return true;
  }
  /// The side ended on its own terms (finished, or stopped because its peer stopped).
  void ExpectCleanEnd(const char* side, const hiltwin::kernel_glue::ExitStatus& status) {
    SCOPED_TRACE(side);
    ASSERT_TRUE(status.exited) << status.Describe();
    EXPECT_TRUE(status.code == 0 || status.code == 3) << ReadFile(Path(side) + ".err");
    const auto report = Report(side);
    EXPECT_EQ(report["outputs_safe"], true);
    ExpectCompleteLog(side, report);
  }
  void ExpectCompleteLog(const char* side, const nlohmann::json& report) {
    std::ifstream in(Path(std::string(side) + ".csv"));
    std::string header;
    ASSERT_TRUE(std::getline(in, header));
    const auto columns = static_cast<std::size_t>(std::count(header.begin(), header.end(), ',')) + 1;
    std::size_t rows = 0;
    std::string line;
    while (std::getline(in, line)) {
      std::stringstream cells(line);
      std::string cell;
      std::size_t n = 0;
      while (std::getline(cells, cell, ',')) {
        std::size_t used = 0;
        EXPECT_NO_THROW((void)std::stod(cell, &used)) << "row " << rows << ": " << line;
        ++n;
      }
      ASSERT_EQ(n, columns) << "row " << rows << ": " << line;
      ++rows;
    }
    EXPECT_GT(rows, 0U);
    EXPECT_EQ(rows, report["log_rows_written"].get<std::size_t>());
  }

  hiltwin::test::WireScratch scratch_{"vandal"};  // a faulted side may leave the segment
  std::optional<hiltwin::kernel_glue::Process> twin_;
  std::optional<hiltwin::kernel_glue::Process> ecs_;
};

TEST_F(WireVandalCli, RandomBytesStopBothSidesOnAnIoFault) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("random");
  const auto twin = End(*twin_);
  const auto ecs = End(*ecs_);
  ExpectCorruptionFault("twin", twin, "wire: ");
  ExpectCorruptionFault("ecs", ecs, "wire: ");
}

TEST_F(WireVandalCli, AChangedMagicStopsBothSides) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("magic");
  const auto twin = End(*twin_);
  const auto ecs = End(*ecs_);
  ExpectCorruptionFault("twin", twin, "the segment's header (state 2, magic 0xbad");
  ExpectCorruptionFault("ecs", ecs, "the segment's header (state 2, magic 0xbad");
}

TEST_F(WireVandalCli, AnAbsurdRingIndexFaultsTheSideThatReadsIt) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("index");
  const auto twin = End(*twin_);
  const auto ecs = End(*ecs_);
  const bool ecs_faulted =
      ExpectCorruptionFaultOrPeerStopped("ecs", ecs, "the ring's newest index jumped from ");
  const bool twin_faulted =
      ExpectCorruptionFaultOrPeerStopped("twin", twin, "but this twin published up to ");
  EXPECT_TRUE(ecs_faulted || twin_faulted) << "neither side read the absurd index";
}

TEST_F(WireVandalCli, AnImpossibleEncoderPeriodStopsTheController) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("period");
  const auto ecs = End(*ecs_);
  const auto twin = End(*twin_);
  ExpectCorruptionFault("ecs", ecs, "has divider 0 (a board uses 4..65535)");
  ExpectCleanEnd("twin", twin);
  EXPECT_EQ(Report("twin")["stop_reason"], "peer_stopped");
}

TEST_F(WireVandalCli, APwmWordOverFullScaleStopsTheTwin) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("pwm");
  const auto twin = End(*twin_);
  const auto ecs = End(*ecs_);
  ExpectCorruptionFault("twin", twin, "wire: PWM word 0 is 0x3fff (magnitude 16383");
  ExpectCleanEnd("ecs", ecs);
  EXPECT_EQ(Report("ecs")["peer_stopped"], "wire: the twin stopped on a fault (see its report)");
}

TEST_F(WireVandalCli, AForgedPidStopsTheSideWhoseEntryItIs) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("pid");
  const auto twin = End(*twin_);
  const auto ecs = End(*ecs_);
  ExpectCorruptionFault("twin", twin, "this side's own entry was overwritten (pid 1, expected ");
  // The controller sees the pid change too; whether it names it (after the settling time) or
  // first sees the twin's announced stop depends on timing: both end it safely.
  ASSERT_TRUE(ecs.exited) << ecs.Describe();
  if (ecs.code == 5) {
    ExpectCorruptionFault("ecs", ecs, "the twin's pid changed from ");
  } else {
    ExpectCleanEnd("ecs", ecs);
  }
}

TEST_F(WireVandalCli, ASeqlockTornForGoodIsALossNotAFault) {
  ASSERT_NO_FATAL_FAILURE(StartPair());  // no vandal on a pair that never met
  Vandalise("torn");
  // Both run to their end: nothing was acted on, nothing hung.
  const auto twin = End(*twin_);
  const auto ecs = End(*ecs_);
  ExpectCleanEnd("twin", twin);
  ExpectCleanEnd("ecs", ecs);
  EXPECT_NE(Report("ecs")["stop_reason"], "io_fault");
}

}  // namespace
