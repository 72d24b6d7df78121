// `hiltwin run` when its files are trouble: a disk that fills under the log, a file-size
// limit, a log path that is a symbolic link, a report in a folder that does not exist. The
// log must end on a whole row, the report must count exactly the rows in the file and say how
// many were lost, and a bad path must be a usage error before the run, touching nothing. A
// report the disk refuses (issue 34, item 3) costs neither the summary nor the previous run's
// report, for `run` and `hil` alike, and a failed rerun leaves the previous report as it was.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kCycles = 80'000;  // 20 s at the default 4 kHz

class RunLogFault : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_run_log_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "small");
    fs::create_directories(dir_ / "out");
  }
  void TearDown() override {
    if (mounted_) ::umount2((dir_ / "small").c_str(), MNT_DETACH);
    fs::remove_all(dir_);
  }

  // A 256 KiB tmpfs on <dir>/small: a disk that really fills. Needs root (CAP_SYS_ADMIN);
  // empty when mounted, else why not.
  std::string MountSmallFileSystem() {
    if (::mount("tmpfs", (dir_ / "small").c_str(), "tmpfs", MS_NOSUID | MS_NODEV | MS_NOEXEC,
                "size=256k,mode=0700") != 0) {
      return std::string("mount tmpfs: ") + std::strerror(errno);
    }
    mounted_ = true;
    return {};
  }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Fills the small file system to its last byte (a file of blocks, then one of bytes).
  void FillSmallFileSystem() {
    for (const std::size_t chunk : {std::size_t{4096}, std::size_t{1}}) {
      std::FILE* filler = std::fopen(Path("small/filler" + std::to_string(chunk)).c_str(), "wb");
      ASSERT_NE(filler, nullptr);
      std::setvbuf(filler, nullptr, _IONBF, 0);
      const std::string block(chunk, 'x');
      while (std::fwrite(block.data(), 1, block.size(), filler) == block.size()) {
      }
      std::fclose(filler);
    }
  }

  // The names in `folder`, sorted: a report's temporary file must not be left behind.
  std::vector<std::string> Names(const std::string& folder) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(Path(folder))) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  static std::vector<std::string> Args(std::vector<std::string> extra) {
    std::vector<std::string> argv = {HILTWIN_BINARY, "run", "--no-progress", "--clock",
                                     "virtual"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  }

  static std::string ReadText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  static nlohmann::json ReadJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }

  // The log's data rows, after checking that it ends with a whole row and that every row has
  // the header's number of fields, each a number.
  static std::uint64_t CheckLogAndCountRows(const std::string& path) {
    const std::string text = ReadText(path);
    EXPECT_FALSE(text.empty());
    if (text.empty()) return 0;
    EXPECT_EQ(text.back(), '\n') << "the log ends in a torn row";
    std::stringstream lines(text);
    std::string header;
    std::getline(lines, header);
    EXPECT_EQ(header.rfind("time_s,", 0), 0U) << header;
    const auto columns = static_cast<std::size_t>(std::count(header.begin(), header.end(), ',')) + 1;
    std::uint64_t rows = 0;
    for (std::string line; std::getline(lines, line); ++rows) {
      std::stringstream cells(line);
      std::size_t fields = 0;
      for (std::string cell; std::getline(cells, cell, ','); ++fields) {
        char* end = nullptr;
        (void)std::strtod(cell.c_str(), &end);
        EXPECT_TRUE(!cell.empty() && *end == '\0') << "row " << rows + 1 << ": '" << cell << "'";
      }
      EXPECT_EQ(fields, columns) << "row " << rows + 1 << ": " << line;
    }
    return rows;
  }

  // What every full-disk run must show: exit 5 naming the reason, a log of whole rows, a
  // report whose written count is the file's and whose counts add up to the rows planned.
  void ExpectExactAccounting(const hiltwin::test::RunResult& r, const std::string& reason,
                             std::uint64_t rows_planned) {
    EXPECT_EQ(r.exit_code, 5) << r.status.Describe() << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
    EXPECT_NE(r.out.find(" lost (" + reason + ")"), std::string::npos) << r.out;
    const auto report = ReadJson(Path("out/r.json"));
    const std::uint64_t rows_in_file = CheckLogAndCountRows(Path("small/run.csv"));
    EXPECT_GT(rows_in_file, 1000U);
    EXPECT_EQ(report["log_rows_written"].get<std::uint64_t>(), rows_in_file);
    EXPECT_EQ(report["log_rows_dropped"].get<std::uint64_t>(), 0U);  // virtual: none
    EXPECT_EQ(report["log_rows_lost"].get<std::uint64_t>(), rows_planned - rows_in_file);
    EXPECT_EQ(report["cycles_run"].get<std::uint64_t>(), kCycles);
    EXPECT_NE(report["log_error"].get<std::string>().find(reason), std::string::npos);
    EXPECT_NE(r.out.find(std::to_string(rows_in_file) + " rows written, 0 dropped, " +
                         std::to_string(rows_planned - rows_in_file) + " lost"),
              std::string::npos)
        << r.out;
  }

  fs::path dir_;
  bool mounted_ = false;
};

TEST_F(RunLogFault, AFullDiskEndsTheLogOnAWholeRowAndTheReportCountsWhatIsInIt) {
  if (const std::string why = MountSmallFileSystem(); !why.empty()) {
    GTEST_SKIP() << why << " (needs root to mount a small file system)";
  }
  const auto r = hiltwin::test::Run(Args({"--duration", "20", "--log", Path("small/run.csv"),
                                          "--report", Path("out/r.json")}));
  ExpectExactAccounting(r, "No space left on device", kCycles);
}

TEST_F(RunLogFault, AFileSizeLimitEndsTheLogLikeAFullDiskNotWithACrash) {
  // prlimit (util-linux) sets RLIMIT_FSIZE and execs hiltwin, which must ignore SIGXFSZ (its
  // default kills the process) so the write fails with EFBIG. The log lives in the plain
  // folder here; the name "small" is only the tests' convention.
  if (!fs::exists("/usr/bin/prlimit")) GTEST_SKIP() << "no /usr/bin/prlimit (util-linux)";
  std::vector<std::string> argv = {"/usr/bin/prlimit", "--fsize=262144", "--"};
  for (const std::string& arg :
       Args({"--duration", "20", "--log-decimation", "3", "--log", Path("small/run.csv"),
             "--report", Path("out/r.json")})) {
    argv.push_back(arg);
  }
  const auto r = hiltwin::test::Run(argv);
  ASSERT_TRUE(r.status.exited) << r.status.Describe() << "\n" << r.err;
  ExpectExactAccounting(r, "File too large", (kCycles + 2) / 3);
  EXPECT_LE(fs::file_size(Path("small/run.csv")), 262144U);
}

TEST_F(RunLogFault, ADiskFullBeforeTheRunIsAnIoErrorAtStart) {
  if (const std::string why = MountSmallFileSystem(); !why.empty()) {
    GTEST_SKIP() << why << " (needs root to mount a small file system)";
  }
  {
    std::ofstream filler(Path("small/filler"), std::ios::binary);
    const std::string block(4096, 'x');
    for (int i = 0; i < 80 && filler; ++i) filler << block;  // 320 KiB: more than fits
  }
  const auto r = hiltwin::test::Run(Args({"--duration", "1", "--log", Path("small/run.csv"),
                                          "--report", Path("out/r.json")}));
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("--log: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  // No run, so no report: the one created before the log failed is removed again.
  EXPECT_FALSE(fs::exists(Path("out/r.json")));
}

TEST_F(RunLogFault, ALogPathThatIsASymbolicLinkIsRefusedAndItsTargetStaysUntouched) {
  const std::string target = Path("out/precious.txt");
  std::ofstream(target) << "keep me\n";
  fs::create_symlink(target, Path("run.csv"));
  fs::create_symlink(Path("out/not_there.csv"), Path("dangling.csv"));
  for (const auto& [flag, link, pointee] :
       {std::tuple{"--log", Path("run.csv"), target},
        std::tuple{"--timing-log", Path("run.csv"), target},
        std::tuple{"--log", Path("dangling.csv"), Path("out/not_there.csv")}}) {
    const auto r = hiltwin::test::Run(Args({"--duration", "1", flag, link}));
    EXPECT_EQ(r.exit_code, 2) << flag << " " << link << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find(std::string(flag) + " " + link + " is a symbolic link (to " + pointee +
                         "); hiltwin does not write through links: name the real file"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out.find("verdict"), std::string::npos) << "a run was performed:\n" << r.out;
  }
  EXPECT_EQ(ReadText(target), "keep me\n");
  EXPECT_FALSE(fs::exists(Path("out/not_there.csv")));  // a dangling link creates nothing
  EXPECT_TRUE(fs::is_symlink(Path("run.csv")));
}

TEST_F(RunLogFault, AReportInAMissingFolderIsAUsageErrorBeforeTheRun) {
  const std::string report = Path("missing/r.json");
  const auto r = hiltwin::test::Run(
      Args({"--duration", "1", "--log", Path("out/run.csv"), "--report", report}));
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--report " + report + ": the folder '" + Path("missing") +
                       "' does not exist; create it first"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out.find("verdict"), std::string::npos) << "a run was performed:\n" << r.out;
  EXPECT_FALSE(fs::exists(Path("out/run.csv")));  // refused before anything was opened
  EXPECT_FALSE(fs::exists(Path("missing")));
}

TEST_F(RunLogFault, AReportPathThatIsASymbolicLinkIsRefused) {
  const std::string target = Path("out/precious.json");
  std::ofstream(target) << "{}\n";
  fs::create_symlink(target, Path("r.json"));
  const auto r = hiltwin::test::Run(Args({"--duration", "1", "--report", Path("r.json")}));
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--report " + Path("r.json") + " is a symbolic link (to " + target + ")"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(ReadText(target), "{}\n");
}

TEST_F(RunLogFault, AFullDiskUnderTheReportPrintsTheSummaryAndKeepsThePreviousReport) {
  if (const std::string why = MountSmallFileSystem(); !why.empty()) {
    GTEST_SKIP() << why << " (needs root to mount a small file system)";
  }
  const std::string report = Path("small/r.json");
  std::ofstream(report) << "{\"previous\": true}\n";
  FillSmallFileSystem();
  const auto r = hiltwin::test::Run(Args({"--duration", "1", "--report", report}));
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  // The whole summary, not only the start line.
  EXPECT_NE(r.out.find("cycles     4000 of 4000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("verdict    PASS"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("hiltwin run: --report " + report +
                       ": cannot write the report (No space left on device)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(ReadText(report), "{\"previous\": true}\n");
  EXPECT_EQ(Names("small"), (std::vector<std::string>{"filler1", "filler4096", "r.json"}));
}

TEST_F(RunLogFault, AFileSizeLimitUnderTheReportIsExitFiveAfterTheSummary) {
  if (!fs::exists("/usr/bin/prlimit")) GTEST_SKIP() << "no /usr/bin/prlimit (util-linux)";
  const std::string report = Path("out/r.json");
  std::vector<std::string> argv = {"/usr/bin/prlimit", "--fsize=1024", "--"};
  for (const std::string& arg : Args({"--duration", "1", "--on-violation", "abort",
                                      "--inject-overrun", "at=100,count=3,extra-us=600",
                                      "--report", report})) {
    argv.push_back(arg);
  }
  const auto r = hiltwin::test::Run(argv);
  // An aborted run (4) whose report cannot be written is an I/O error (5), said on stderr.
  EXPECT_EQ(r.exit_code, 5) << r.status.Describe() << "\n" << r.out << r.err;
  EXPECT_NE(r.out.find("verdict    ABORTED"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("--report " + report + ": cannot write the report (File too large)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(Names("out"), std::vector<std::string>{});  // no report, no temporary file
}

TEST_F(RunLogFault, AFailedRerunLeavesThePreviousReportAsItWas) {
  const std::string report = Path("out/r.json");
  const auto first = hiltwin::test::Run(Args({"--duration", "0.1", "--report", report}));
  ASSERT_EQ(first.exit_code, 0) << first.out << first.err;
  const std::string previous = ReadText(report);
  ASSERT_NE(previous.find("\"verdict\": \"PASS\""), std::string::npos) << previous;
  // The wrong image stops at INIT (exit 5); a missing --config is bad input (exit 2).
  for (const auto& [flag, value, code] :
       {std::tuple{"--board-image", std::string("icoboard"), 5},
        std::tuple{"--config", Path("missing.toml"), 2}}) {
    const auto r = hiltwin::test::Run(Args({"--duration", "0.1", "--report", report, flag, value}));
    EXPECT_EQ(r.exit_code, code) << flag << "\n" << r.out << r.err;
    EXPECT_EQ(ReadText(report), previous) << flag;
    EXPECT_EQ(Names("out"), std::vector<std::string>{"r.json"}) << flag;
  }
}

TEST_F(RunLogFault, HilPrintsItsSummaryAndKeepsThePreviousCombinedReportOnAFullDisk) {
  if (const std::string why = MountSmallFileSystem(); !why.empty()) {
    GTEST_SKIP() << why << " (needs root to mount a small file system)";
  }
  const std::string report = Path("small/hil.json");
  std::ofstream(report) << "{\"previous\": true}\n";
  FillSmallFileSystem();
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "hil", "--clock", "virtual", "--duration",
                                     "1", "--no-progress", "--report", report});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.out.find("hil       exit 0 (the worse of twin 0 and ECS 0)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("hiltwin hil: --report " + report +
                       ": cannot write the report (No space left on device)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(ReadText(report), "{\"previous\": true}\n");
  EXPECT_EQ(Names("small"), (std::vector<std::string>{"filler1", "filler4096", "hil.json"}));
}

}  // namespace
