// `hiltwin doctor` end to end: on this machine (whatever it is: a VM, a container, a PREEMPT_RT
// box) and on an empty file tree where every /sys and /proc file is missing. Both must give
// one line per check with a known status and exit 0; the doctor reports, it does not crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;

const std::set<std::string> kCheckIds = {
    "preemption",   "sched_fifo",     "mlockall", "rlimit_rtprio", "rlimit_memlock",
    "capabilities", "cpu_dma_latency", "governor", "isolated_cpus", "rt_throttling",
    "smt",          "clocksource",    "cpus_online", "virtualisation", "steal_time"};

void ExpectEveryCheckOnce(const nlohmann::json& report) {
  ASSERT_TRUE(report.contains("checks")) << report.dump();
  std::set<std::string> seen;
  int ok = 0, warn = 0, bad = 0;
  for (const auto& check : report["checks"]) {
    const auto id = check["id"].get<std::string>();
    EXPECT_TRUE(seen.insert(id).second) << "check listed twice: " << id;
    EXPECT_FALSE(check["value"].get<std::string>().empty()) << id;
    const auto status = check["status"].get<std::string>();
    ok += status == "ok";
    warn += status == "warn";
    bad += status == "bad";
    EXPECT_TRUE(status == "ok" || status == "warn" || status == "bad") << id << ": " << status;
    // Anything not ok must say what to do.
    if (status != "ok") {
      EXPECT_FALSE(check["advice"].get<std::string>().empty()) << id;
    }
  }
  EXPECT_EQ(seen, kCheckIds);
  EXPECT_EQ(report["summary"]["ok"], ok);
  EXPECT_EQ(report["summary"]["warn"], warn);
  EXPECT_EQ(report["summary"]["bad"], bad);
}

TEST(DoctorCli, JsonOnThisMachineListsEveryCheck) {
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "doctor", "--json", "--steal-ms", "50"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ExpectEveryCheckOnce(nlohmann::json::parse(r.out));
}

TEST(DoctorCli, EmptyTreeGivesUnknownsNotACrash) {
  const fs::path root = fs::temp_directory_path() / ("hiltwin_doctor_" + std::to_string(getpid()));
  fs::create_directories(root);
  const auto r = hiltwin::test::Run(
      {HILTWIN_BINARY, "doctor", "--json", "--no-try", "--steal-ms", "0", "--root", root.string()});
  fs::remove_all(root);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  ExpectEveryCheckOnce(report);
  // With no files at all, the kernel checks cannot claim to know the answer.
  for (const auto& check : report["checks"]) {
    if (check["id"] == "preemption" || check["id"] == "governor") {
      EXPECT_NE(check["status"], "ok") << check.dump();
    }
  }
}

TEST(DoctorCli, TextSaysWhatToDoAndBadUsageExitsTwo) {
  const auto text = hiltwin::test::Run({HILTWIN_BINARY, "doctor", "--steal-ms", "0", "--no-try"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("preemption"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("docs/realtime-setup.md"), std::string::npos);
  const auto bad = hiltwin::test::Run({HILTWIN_BINARY, "doctor", "--steal-ms", "-5"});
  EXPECT_EQ(bad.exit_code, 2);
  const auto missing = hiltwin::test::Run({HILTWIN_BINARY, "doctor", "--root", "/no/such/dir"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("--root"), std::string::npos) << missing.err;
}

}  // namespace
