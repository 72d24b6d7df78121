// Outputs never clobber inputs or each other (issue 34, item 2): every command that takes file
// inputs and outputs refuses, with exit 2 and before it creates anything, an output that names
// the file of an input or of another output, however the two paths are spelled (another
// spelling, a hard link, a linked folder), and the input stays exactly as it was. Each case is
// refused at the command line, so the whole suite takes well under a second.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;

class OutputPathsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_output_paths_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "logs");
    const fs::path source(HILTWIN_SOURCE_DIR);
    fs::copy_file(source / "relbot/relbot.toml", dir_ / "cfg.toml");
    fs::copy_file(source / "relbot/relbot_map.toml", dir_ / "map.toml");
    fs::copy_file(source / "relbot/ecs_gains.toml", dir_ / "gains.toml");
    std::ofstream(dir_ / "prof.csv") << "time,left,right\n0,0,0\n1,0.5,0.5\n2,0,0\n";
    std::ofstream(dir_ / "sp.csv") << "time,left_m,right_m\n0,0,0\n1,0.1,0.1\n";
    std::ofstream csv(dir_ / "run.csv");
    csv << "time_s,sim,exp\n";
    for (int i = 0; i <= 200; ++i) csv << i * 0.01 << ',' << i << ',' << i + 1 << '\n';
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  static std::string ReadText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  /// `hiltwin ARGS` must be refused with exit 2 naming both flags as the same file, run nothing
  /// and leave every file of the folder as it was (none created, none changed, none removed).
  void ExpectRefused(const std::vector<std::string>& args, const std::string& first,
                     const std::string& second) {
    std::vector<std::pair<fs::path, std::string>> before;
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      if (entry.is_regular_file()) before.emplace_back(entry.path(), ReadText(entry.path()));
    }
    std::vector<std::string> argv = {HILTWIN_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto r = hiltwin::test::Run(argv);
    const std::string what = args[0] + " " + first + " / " + second;
    EXPECT_EQ(r.exit_code, 2) << what << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find(first + " and " + second + " name the same file: "), std::string::npos)
        << what << "\n" << r.err;
    EXPECT_EQ(r.out.find("verdict"), std::string::npos) << what << ": a run was performed";
    std::size_t files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      if (entry.is_regular_file()) ++files;
    }
    EXPECT_EQ(files, before.size()) << what << ": a file was created or removed";
    for (const auto& [path, text] : before) {
      EXPECT_TRUE(ReadText(path) == text) << what << ": " << path << " changed or removed";
    }
  }

  fs::path dir_;
};

TEST_F(OutputPathsCli, TwoOutputsOnOneFileAreRefusedBeforeEitherIsCreated) {
  const std::string x = Path("x.csv");
  ExpectRefused({"run", "--clock", "virtual", "--duration", "0.1", "--log", x, "--report", x},
                "--log " + x, "--report " + x);
  // Another spelling of a file that does not exist yet is the same file.
  const std::string s = Path("s.csv");
  const std::string s_again = Path("logs/../s.csv");
  ExpectRefused(
      {"run", "--clock", "virtual", "--duration", "0.1", "--log", s, "--timing-log", s_again},
      "--log " + s, "--timing-log " + s_again);
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "run", "--clock", "virtual", "--duration",
                                     "0.1", "--log", x, "--report", x});
  EXPECT_NE(r.err.find("each output would overwrite the other; give each its own file"),
            std::string::npos)
      << r.err;
}

TEST_F(OutputPathsCli, RunRefusesAnOutputOnAnyOfItsInputsAndKeepsTheInput) {
  const std::vector<std::string> run = {"run", "--clock", "virtual", "--duration", "0.1"};
  const auto with = [&run](std::vector<std::string> more) {
    std::vector<std::string> args = run;
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  const std::string prof = Path("prof.csv");
  const std::string cfg = Path("cfg.toml");
  const std::string map = Path("map.toml");
  ExpectRefused(with({"--input", prof, "--log", prof}), "--log " + prof, "--input " + prof);
  // Before: the report was created (empty) before --config was read, and removed on the error.
  ExpectRefused(with({"--config", cfg, "--report", cfg}), "--report " + cfg, "--config " + cfg);
  ExpectRefused(with({"--plant-map", map, "--report", map}), "--report " + map,
                "--plant-map " + map);
  // A hard link and a linked folder name the same file under another name.
  fs::create_hard_link(cfg, Path("hard.toml"));
  fs::create_directory_symlink(dir_, Path("linked"));
  const std::string hard = Path("hard.toml");
  const std::string linked = Path("linked/cfg.toml");
  ExpectRefused(with({"--config", cfg, "--timing-log", hard}), "--timing-log " + hard,
                "--config " + cfg);
  ExpectRefused(with({"--config", linked, "--log", cfg}), "--log " + cfg, "--config " + linked);
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "run", "--clock", "virtual", "--duration",
                                     "0.1", "--input", prof, "--log", prof});
  EXPECT_NE(r.err.find("--log would overwrite the file --input reads; give --log another file"),
            std::string::npos)
      << r.err;
}

TEST_F(OutputPathsCli, EcsHilTuneAssessAndTraceRefuseItToo) {
  const std::string gains = Path("gains.toml");
  const std::string sp = Path("sp.csv");
  const std::string cfg = Path("cfg.toml");
  const std::string logs = Path("logs");
  ExpectRefused({"ecs", "--clock", "virtual", "--gains", gains, "--log", gains}, "--log " + gains,
                "--gains " + gains);
  ExpectRefused({"ecs", "--clock", "virtual", "--setpoint", sp, "--report", sp},
                "--report " + sp, "--setpoint " + sp);
  ExpectRefused({"hil", "--clock", "virtual", "--config", cfg, "--report", cfg},
                "--report " + cfg, "--config " + cfg);
  // The files hil keeps in --log-dir are outputs too.
  const std::string twin_report = Path("logs/twin.json");
  ExpectRefused({"hil", "--clock", "virtual", "--log-dir", logs, "--report", twin_report},
                "--report " + twin_report, "--log-dir " + twin_report);
  ExpectRefused({"tune", "--clock", "virtual", "--inject-compute-us", "85", "--inject-overhead-us",
                 "35", "--inject-latency-us", "0", "--config", cfg, "--report", cfg},
                "--report " + cfg, "--config " + cfg);
  const std::string r_json = Path("r.json");
  ExpectRefused({"tune", "--clock", "virtual", "--inject-compute-us", "85", "--inject-overhead-us",
                 "35", "--inject-latency-us", "0", "--report", r_json, "--plot", r_json},
                "--report " + r_json, "--plot " + r_json);
  const std::string run_csv = Path("run.csv");
  ExpectRefused({"assess", run_csv, "--plot", run_csv}, "--plot " + run_csv, "FILE " + run_csv);
  ExpectRefused({"assess", "--sim", run_csv + ":2", "--exp", run_csv + ":3", "--plot", run_csv},
                "--plot " + run_csv, "--sim " + run_csv);
  // trace writes its own files into --output: a run output there may not take one's name.
  const std::string trace_report = Path("logs/run_report.json");
  ExpectRefused({"trace", "--clock", "virtual", "--duration", "0.1", "--output", logs,
                 "--report", trace_report},
                "--report " + trace_report, "--output " + trace_report);
}

TEST_F(OutputPathsCli, ABuiltInProfileNameIsNotAFileAndTwoInputsMayShareOne) {
  // `--input openloop` is the built-in profile, whatever a file of that name holds.
  const auto r = hiltwin::test::Run({"/usr/bin/env", "-C", dir_.string(), HILTWIN_BINARY, "run",
                                     "--no-progress", "--clock", "virtual", "--duration", "0.1",
                                     "--input", "openloop", "--log", "openloop"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(ReadText(Path("openloop")).rfind("time_s,", 0), 0U);
  // Two inputs reading one file are no conflict (assess's --sim and --exp from one log).
  const auto a = hiltwin::test::Run({HILTWIN_BINARY, "assess", "--sim", Path("run.csv") + ":2",
                                     "--exp", Path("run.csv") + ":3"});
  EXPECT_EQ(a.exit_code, 0) << a.out << a.err;
}

}  // namespace
