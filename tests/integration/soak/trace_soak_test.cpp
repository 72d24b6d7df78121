// `hiltwin trace` at 20 kHz for 60 s (issue: "no discarded events at 20 kHz for 60 s"): the
// channel sized for the rate keeps every event, and the trace's report agrees with the run's.
// Opt-in (label soak): a minute of real time plus the analysis of 1.2 M cycles.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;

TEST(TraceSoak, TwentyKilohertzForAMinuteDiscardsNoEvent) {
  const fs::path dir =
      fs::temp_directory_path() / ("hiltwin_trace_soak_" + std::to_string(getpid()));
  fs::remove_all(dir);
  const auto r = hiltwin::test::Run(
      {HILTWIN_BINARY, "trace", "--output", (dir / "t").string(), "--rate", "20000", "--duration",
       "60", "--no-progress", "--report", (dir / "run.json").string()},
      600'000);
  ASSERT_LE(r.exit_code, 4) << r.err;
  std::ifstream jitter_in(dir / "t" / "jitter_report.json");
  const nlohmann::json jitter = nlohmann::json::parse(jitter_in);
  std::ifstream run_in(dir / "run.json");
  const nlohmann::json run = nlohmann::json::parse(run_in);
  EXPECT_EQ(jitter["discarded_events"].get<std::uint64_t>(), 0U);
  EXPECT_EQ(jitter["cycles"].get<std::uint64_t>(), 1'200'000U);
  EXPECT_EQ(jitter["cycles"], run["cycles_run"]);
  EXPECT_EQ(jitter["deadline_misses"], run["deadline_misses"]);
  EXPECT_TRUE(jitter["warnings"].empty()) << jitter["warnings"].dump(2);
  fs::remove_all(dir);
}

}  // namespace
