// The CSV log on a file system that fills up, and under a file-size limit: the log ends with
// a whole row, rows_written() counts exactly the rows in the file, and every selected row is
// written, dropped or lost (csv_logger.h "Accounting").
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "hiltwin/tracing/csv_logger.h"

namespace hiltwin::tracing {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kColumns = 9;  // as wide as the twin's log
// 8 MiB of rows or more: far beyond the 256 KiB file system and the 256 KiB write buffer.
constexpr int kRows = 100'000;

std::vector<std::string> ColumnNames() {
  std::vector<std::string> names;
  for (std::size_t c = 0; c < kColumns; ++c) names.push_back("v" + std::to_string(c));
  return names;
}

// Row k's values: distinct per row and column, so a line tells which row it is.
std::array<double, kColumns> RowValues(int k) {
  std::array<double, kColumns> values{};
  for (std::size_t c = 0; c < kColumns; ++c) values[c] = k * 1.5 + static_cast<double>(c) / 8.0;
  return values;
}

double RowTime(int k) { return k * 0.00025; }

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Checks the file's shape and returns its data-line count: it ends with '\n', every data line
// is a whole row of the sequence above (every column parses and matches its time), in order,
// a multiple of `decimation` apart; with `contiguous` (nothing dropped) line n holds row
// n * `decimation`.
std::size_t CheckLogAndCountRows(const std::string& path, int decimation, bool contiguous) {
  const std::string text = ReadAll(path);
  EXPECT_FALSE(text.empty());
  if (text.empty()) return 0;
  EXPECT_EQ(text.back(), '\n') << "the log ends in a torn row";
  std::stringstream lines(text);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line.rfind("time_s,v0,", 0), 0U) << line;
  std::size_t rows = 0;
  int previous = -decimation;
  while (std::getline(lines, line)) {
    std::vector<double> fields;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      char* end = nullptr;
      fields.push_back(std::strtod(cell.c_str(), &end));
      EXPECT_EQ(*end, '\0') << "line " << rows + 2 << ": '" << cell << "'";
    }
    EXPECT_EQ(fields.size(), kColumns + 1) << "line " << rows + 2 << ": " << line;
    if (fields.size() == kColumns + 1) {
      const int k = static_cast<int>(std::lround(fields[0] / RowTime(1)));
      if (contiguous) {
        EXPECT_EQ(k, static_cast<int>(rows) * decimation) << "line " << rows + 2;
      }
      EXPECT_GT(k, previous) << "line " << rows + 2;
      EXPECT_EQ(k % decimation, 0) << "line " << rows + 2;
      EXPECT_EQ(fields[0], RowTime(k)) << "line " << rows + 2;
      EXPECT_EQ(fields[kColumns], RowValues(k)[kColumns - 1]) << "line " << rows + 2;
      previous = k;
    }
    ++rows;
  }
  return rows;
}

CsvLoggerConfig Config(const std::string& path) {
  CsvLoggerConfig config;
  config.path = path;
  config.columns = ColumnNames();
  return config;
}

// Offers kRows rows of the sequence, then stops the logger.
void LogAll(CsvLogger& logger) {
  for (int k = 0; k < kRows; ++k) (void)logger.TryLog(RowTime(k), RowValues(k));
  logger.Stop();
}

class CsvLoggerFullDiskTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("hiltwin_csv_full_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    fs::remove_all(dir_);
  }

  // A 256 KiB tmpfs on the test's folder: a disk that really fills up. Needs root
  // (CAP_SYS_ADMIN); empty when mounted, else why not.
  std::string MountSmallFileSystem() {
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", MS_NOSUID | MS_NODEV | MS_NOEXEC,
                "size=256k,mode=0700") != 0) {
      return std::string("mount tmpfs: ") + std::strerror(errno);
    }
    mounted_ = true;
    return {};
  }

  [[nodiscard]] std::string Path() const { return (dir_ / "log.csv").string(); }

  fs::path dir_;
  bool mounted_ = false;
};

TEST_F(CsvLoggerFullDiskTest, FullFileSystemEndsOnAWholeRowAndCountsEveryRow) {
  if (const std::string why = MountSmallFileSystem(); !why.empty()) {
    GTEST_SKIP() << why << " (needs root to mount a small file system)";
  }
  auto config = Config(Path());
  config.wait_when_full = true;  // off-line mode: nothing is dropped, so every loss is the disk's
  CsvLogger logger(config);
  logger.Start();
  LogAll(logger);

  EXPECT_NE(logger.error().find("No space left on device"), std::string::npos) << logger.error();
  EXPECT_NE(logger.error().find(Path()), std::string::npos) << logger.error();
  EXPECT_EQ(logger.error_reason(), "No space left on device");
  EXPECT_LE(fs::file_size(Path()), 256U * 1024U);
  const std::size_t rows_in_file = CheckLogAndCountRows(Path(), 1, true);
  EXPECT_GT(rows_in_file, 1000U);  // ~2,900 rows of this width fit
  EXPECT_EQ(logger.rows_written(), rows_in_file);
  EXPECT_EQ(logger.rows_dropped(), 0U);
  EXPECT_EQ(logger.rows_lost(), kRows - rows_in_file);
  EXPECT_EQ(logger.rows_selected(), static_cast<std::uint64_t>(kRows));
  EXPECT_EQ(logger.rows_written() + logger.rows_dropped() + logger.rows_lost(),
            logger.rows_selected());
}

TEST_F(CsvLoggerFullDiskTest, DropsAndDiskLossesAreCountedOnceEach) {
  // A queue that overflows (drops) on a disk that fills (losses), with decimation, so
  // "selected" is not "offered". No writer thread: Flush drains in this thread, so which rows
  // are dropped is exact: each burst selects 512 rows, 256 fit in the queue.
  if (const std::string why = MountSmallFileSystem(); !why.empty()) {
    GTEST_SKIP() << why << " (needs root to mount a small file system)";
  }
  constexpr int kDecimation = 3;
  constexpr int kBurstOffers = 512 * kDecimation;
  constexpr int kBursts = 40;  // 10,240 queued rows, several times what the disk holds
  auto config = Config(Path());
  config.queue_capacity_rows = 256;
  config.decimation = kDecimation;
  CsvLogger logger(config);
  for (int burst = 0; burst < kBursts; ++burst) {
    for (int i = 0; i < kBurstOffers; ++i) {
      const int k = burst * kBurstOffers + i;
      (void)logger.TryLog(RowTime(k), RowValues(k));
    }
    logger.Flush();
  }
  logger.Stop();

  const std::size_t rows_in_file = CheckLogAndCountRows(Path(), kDecimation, false);
  EXPECT_EQ(logger.rows_written(), rows_in_file);
  EXPECT_EQ(logger.rows_selected(), static_cast<std::uint64_t>(kBursts) * 512U);
  EXPECT_EQ(logger.rows_dropped(), static_cast<std::uint64_t>(kBursts) * 256U);
  EXPECT_EQ(logger.rows_lost(), kBursts * 256U - rows_in_file);
  EXPECT_EQ(logger.rows_written() + logger.rows_dropped() + logger.rows_lost(),
            logger.rows_selected());
  EXPECT_EQ(logger.error_reason(), "No space left on device");
}

// What the forked child reports through its pipe (a pipe is not subject to RLIMIT_FSIZE).
struct ChildFigures {
  std::uint64_t written = 0;
  std::uint64_t dropped = 0;
  std::uint64_t lost = 0;
  std::uint64_t selected = 0;
  char reason[128] = {};
};

// In the child: SIGXFSZ ignored (as the hiltwin binary does), a file-size limit, one logger.
[[noreturn]] void LogUnderFileSizeLimit(const std::string& path, rlim_t limit_bytes, int out_fd) {
  ::signal(SIGXFSZ, SIG_IGN);
  const rlimit limit{limit_bytes, limit_bytes};
  if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(2);
  ChildFigures figures;
  {
    auto config = Config(path);
    config.wait_when_full = true;
    CsvLogger logger(config);
    logger.Start();
    LogAll(logger);
    figures = {logger.rows_written(), logger.rows_dropped(), logger.rows_lost(),
               logger.rows_selected(), {}};
    std::strncpy(figures.reason, logger.error_reason().c_str(), sizeof figures.reason - 1);
  }
  const bool sent = ::write(out_fd, &figures, sizeof figures) == sizeof figures;
  ::_exit(sent ? 0 : 3);
}

TEST_F(CsvLoggerFullDiskTest, FileSizeLimitEndsOnAWholeRowAndCountsEveryRow) {
  constexpr rlim_t kLimitBytes = 100 * 1024;  // not a multiple of the row length
  int ends[2];
  ASSERT_EQ(::pipe(ends), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0) << std::strerror(errno);
  if (child == 0) {
    ::close(ends[0]);
    LogUnderFileSizeLimit(Path(), kLimitBytes, ends[1]);
  }
  ::close(ends[1]);
  ChildFigures figures;
  const ssize_t got = ::read(ends[0], &figures, sizeof figures);
  ::close(ends[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child was killed by signal " << WTERMSIG(status);
  ASSERT_EQ(WEXITSTATUS(status), 0);
  ASSERT_EQ(got, static_cast<ssize_t>(sizeof figures));

  EXPECT_STREQ(figures.reason, "File too large");
  EXPECT_LE(fs::file_size(Path()), kLimitBytes);
  const std::size_t rows_in_file = CheckLogAndCountRows(Path(), 1, true);
  EXPECT_GT(rows_in_file, 500U);
  EXPECT_EQ(figures.written, rows_in_file);
  EXPECT_EQ(figures.dropped, 0U);
  EXPECT_EQ(figures.selected, static_cast<std::uint64_t>(kRows));
  EXPECT_EQ(figures.written + figures.dropped + figures.lost, figures.selected);
}

}  // namespace
}  // namespace hiltwin::tracing
