#include "hiltwin/tracing/csv_logger.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fakes/alloc_counter.h"

namespace hiltwin::tracing {
namespace {

namespace fs = std::filesystem;

#if defined(HILTWIN_UNDER_SANITIZER)
constexpr std::uint64_t kStressRows = 50'000;
#else
constexpr std::uint64_t kStressRows = 300'000;
#endif

class CsvLoggerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("hiltwin_csv_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string Path(const std::string& name = "log.csv") const {
    return (dir_ / name).string();
  }

  static std::vector<std::string> ReadLines(const std::string& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }

  // Parses the data rows (header skipped) with strtod, as MATLAB or any C reader would.
  static std::vector<std::vector<double>> ReadRows(const std::string& path) {
    std::vector<std::vector<double>> rows;
    const auto lines = ReadLines(path);
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<double> row;
      std::stringstream fields(lines[i]);
      for (std::string field; std::getline(fields, field, ',');) {
        char* end = nullptr;
        row.push_back(std::strtod(field.c_str(), &end));
        EXPECT_EQ(*end, '\0') << "unparsed text in '" << field << "' on line " << i + 1;
      }
      rows.push_back(row);
    }
    return rows;
  }

  fs::path dir_;
};

CsvLoggerConfig Config(std::string path, std::vector<std::string> columns) {
  CsvLoggerConfig config;
  config.path = std::move(path);
  config.columns = std::move(columns);
  return config;
}

TEST_F(CsvLoggerTest, WritesHeaderThenOneRowPerLoggedCycle) {
  {
    CsvLogger logger(Config(Path(), {"duty_left", "x_m"}));
    logger.Start();
    EXPECT_TRUE(logger.TryLog(0.0, std::array{0.5, 1.25}));
    EXPECT_TRUE(logger.TryLog(0.00025, std::array{-0.5, 2.0}));
    logger.Stop();
    EXPECT_EQ(logger.rows_written(), 2U);
    EXPECT_EQ(logger.rows_dropped(), 0U);
    EXPECT_EQ(logger.rows_offered(), 2U);
    EXPECT_EQ(logger.error(), "");
  }
  const auto lines = ReadLines(Path());
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[0], "time_s,duty_left,x_m");
  EXPECT_EQ(lines[1], "0,0.5,1.25");
  EXPECT_EQ(lines[2], "0.00025,-0.5,2");
}

TEST_F(CsvLoggerTest, WaitWhenFullLosesNothingThroughATinyQueue) {
  auto config = Config(Path(), {"k"});
  config.queue_capacity_rows = 4;
  config.wait_when_full = true;  // off-line (virtual clock) mode
  {
    CsvLogger logger(config);
    logger.Start();
    for (int k = 0; k < 800; ++k) {
      ASSERT_TRUE(logger.TryLog(k * 1e-3, std::array{static_cast<double>(k)}));
    }
    logger.Stop();
    EXPECT_EQ(logger.rows_written(), 800U);
    EXPECT_EQ(logger.rows_dropped(), 0U);
  }
  const auto lines = ReadLines(Path());
  ASSERT_EQ(lines.size(), 801U);
  EXPECT_EQ(lines.back(), "0.799,799");
}

TEST_F(CsvLoggerTest, HeaderIsOnDiskRightAfterConstruction) {
  CsvLogger logger(Config(Path(), {"a"}));
  const auto lines = ReadLines(Path());
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_EQ(lines[0], "time_s,a");
}

TEST_F(CsvLoggerTest, ValuesRoundTripBitExactly) {
  std::mt19937_64 rng(12345);
  std::vector<std::array<double, 4>> sent;
  // Random bit patterns cover every exponent, subnormals included.
  while (sent.size() < 2000) {
    std::array<double, 4> row{};
    for (double& v : row) {
      v = std::bit_cast<double>(rng());
      if (!std::isfinite(v)) v = 1.0 / 3.0;
    }
    sent.push_back(row);
  }
  sent.push_back({-0.0, std::numeric_limits<double>::denorm_min(),
                  std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest()});
  sent.push_back({0.1, 1e-300, 123456789.123456789, -2.5e-7});
  // Whole numbers take the integer path up to 2^53, the double path from there.
  sent.push_back({100000.0, -9007199254740991.0, 9007199254740992.0, 4503599627370495.5});
  // Values with at most 6 decimals below 10^6 take the fixed-point path; near misses do not.
  sent.push_back({999999.999999, -0.000001, 0.0000005, 123.4567891});
  // Multiples of 2^-11 (PWM duty) take the dyadic path; 2^-12 steps do not.
  sent.push_back({1638.0 / 2048.0, -2047.0 / 2048.0, 999999.0 + 2047.0 / 2048.0, 1.0 / 4096.0});
  std::uniform_int_distribution<std::int64_t> micros(-999'999'999'999, 999'999'999'999);
  for (int i = 0; i < 2000; ++i) {
    std::array<double, 4> row{};
    for (double& v : row) v = static_cast<double>(micros(rng)) / 1e6;
    row[3] = static_cast<double>(i) * 0.00025;  // time stamps of a 4 kHz run
    sent.push_back(row);
  }
  CsvLogger logger(Config(Path(), {"a", "b", "c", "d"}));
  logger.Start();
  for (std::size_t i = 0; i < sent.size(); ++i) {
    ASSERT_TRUE(logger.TryLog(static_cast<double>(i) * 0.00025, sent[i]));
  }
  logger.Stop();
  const auto rows = ReadRows(Path());
  ASSERT_EQ(rows.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 5U);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(rows[i][0]),
              std::bit_cast<std::uint64_t>(static_cast<double>(i) * 0.00025));
    for (std::size_t c = 0; c < 4; ++c) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(rows[i][c + 1]),
                std::bit_cast<std::uint64_t>(sent[i][c]))
          << "row " << i << " column " << c << " sent " << sent[i][c] << " got " << rows[i][c + 1];
    }
  }
}

TEST_F(CsvLoggerTest, WholeAndSixDecimalNumbersArePrintedPlainly) {
  CsvLogger logger(Config(Path(), {"a", "b", "c", "d"}));
  ASSERT_TRUE(logger.TryLog(2.0, std::array{100000.0, -3.0, 0.25, -0.0}));
  ASSERT_TRUE(logger.TryLog(4.99975, std::array{-0.5, 1e7, 12.000001, 1e-7}));
  ASSERT_TRUE(logger.TryLog(5.0, std::array{1638.0 / 2048.0, -1.0 / 2048.0, 1.0 / 4096.0, 0.1}));
  logger.Stop();
  const auto lines = ReadLines(Path());
  ASSERT_EQ(lines.size(), 4U);
  EXPECT_EQ(lines[1], "2,100000,-3,0.25,-0");  // not 1e+05; the sign of -0 kept
  EXPECT_EQ(lines[2], "4.99975,-0.5,10000000,12.000001,1e-07");
  EXPECT_EQ(lines[3], "5,0.7998046875,-0.00048828125,0.000244140625,0.1");
}

TEST_F(CsvLoggerTest, NonFiniteValuesUseMatlabSpelling) {
  CsvLogger logger(Config(Path(), {"a", "b", "c"}));
  ASSERT_TRUE(logger.TryLog(1.0, std::array{std::numeric_limits<double>::quiet_NaN(),
                                            std::numeric_limits<double>::infinity(),
                                            -std::numeric_limits<double>::infinity()}));
  logger.Stop();
  const auto lines = ReadLines(Path());
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_EQ(lines[1], "1,NaN,Inf,-Inf");
  const auto rows = ReadRows(Path());
  EXPECT_TRUE(std::isnan(rows[0][1]));
  EXPECT_EQ(rows[0][2], std::numeric_limits<double>::infinity());
  EXPECT_EQ(rows[0][3], -std::numeric_limits<double>::infinity());
}

TEST_F(CsvLoggerTest, DecimationLogsEveryNthOfferStartingWithTheFirst) {
  auto config = Config(Path(), {"k"});
  config.decimation = 3;
  CsvLogger logger(config);
  logger.Start();
  for (int k = 0; k < 10; ++k) {
    EXPECT_TRUE(logger.TryLog(k * 0.001, std::array{static_cast<double>(k)}));
  }
  logger.Stop();
  EXPECT_EQ(logger.rows_offered(), 10U);
  EXPECT_EQ(logger.rows_written(), 4U);
  EXPECT_EQ(logger.rows_dropped(), 0U);
  const auto rows = ReadRows(Path());
  ASSERT_EQ(rows.size(), 4U);
  EXPECT_EQ(rows[0][1], 0.0);
  EXPECT_EQ(rows[1][1], 3.0);
  EXPECT_EQ(rows[2][1], 6.0);
  EXPECT_EQ(rows[3][1], 9.0);
}

TEST_F(CsvLoggerTest, FullQueueWithStalledWriterDropsAndCountsExactly) {
  auto config = Config(Path(), {"k"});
  config.queue_capacity_rows = 4;
  CsvLogger logger(config);  // writer not started: nothing drains the queue
  int accepted = 0;
  for (int k = 0; k < 10; ++k) {
    if (logger.TryLog(k, std::array{static_cast<double>(k)})) ++accepted;
  }
  EXPECT_EQ(accepted, 4);
  EXPECT_EQ(logger.rows_dropped(), 6U);
  EXPECT_EQ(logger.rows_written(), 0U);
  logger.Stop();  // drains what was queued even though no writer ever ran
  EXPECT_EQ(logger.rows_written(), 4U);
  EXPECT_EQ(logger.rows_dropped(), 6U);
  EXPECT_EQ(logger.rows_offered(), 10U);
  const auto rows = ReadRows(Path());
  ASSERT_EQ(rows.size(), 4U);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(rows[static_cast<std::size_t>(k)][1], k);
}

TEST_F(CsvLoggerTest, DropsCountOnlyRowsThatDecimationSelected) {
  auto config = Config(Path(), {"k"});
  config.queue_capacity_rows = 4;
  config.decimation = 2;
  CsvLogger logger(config);
  for (int k = 0; k < 20; ++k) (void)logger.TryLog(k, std::array{static_cast<double>(k)});
  logger.Stop();
  EXPECT_EQ(logger.rows_offered(), 20U);
  EXPECT_EQ(logger.rows_written(), 4U);
  EXPECT_EQ(logger.rows_dropped(), 6U);  // 10 selected, 4 fit
  EXPECT_EQ(logger.rows_selected(), 10U);
  EXPECT_EQ(logger.rows_lost(), 0U);
}

TEST_F(CsvLoggerTest, WrongWidthAndAfterStopRowsAreCountedAsDropped) {
  CsvLogger logger(Config(Path(), {"a", "b"}));
  EXPECT_FALSE(logger.TryLog(0.0, std::array{1.0}));
  EXPECT_FALSE(logger.TryLog(0.0, std::array{1.0, 2.0, 3.0}));
  EXPECT_TRUE(logger.TryLog(0.0, std::array{1.0, 2.0}));
  logger.Stop();
  EXPECT_FALSE(logger.TryLog(1.0, std::array{1.0, 2.0}));
  EXPECT_EQ(logger.rows_written(), 1U);
  EXPECT_EQ(logger.rows_dropped(), 3U);
  EXPECT_EQ(ReadRows(Path()).size(), 1U);
}

TEST_F(CsvLoggerTest, TryLogAllocatesNothing) {
  auto config = Config(Path(), {"a", "b", "c"});
  config.queue_capacity_rows = 256;
  config.decimation = 2;
  CsvLogger logger(config);
  logger.Start();
  const std::array values{1.0, 2.0, 3.0};
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount counter;
    // More offers than the queue holds, so the full-queue path runs too.
    for (int k = 0; k < 5000; ++k) (void)logger.TryLog(k * 1e-3, values);
    allocations = counter.count();
  }
  EXPECT_EQ(allocations, 0U);
  logger.Stop();
  EXPECT_EQ(logger.rows_written() + logger.rows_dropped(), 2500U);
}

TEST_F(CsvLoggerTest, StopWritesEveryRowUpToTheLastCycle) {
  // The shape of a SIGINT stop: the loop thread logs until told to stop, exits, then the
  // control thread calls Stop. Every logged cycle must be in the file afterwards.
  auto config = Config(Path(), {"k"});
  config.writer_poll_period_ns = 5'000'000;  // slow writer: most rows still queued at Stop
  CsvLogger logger(config);
  logger.Start();
  std::atomic<bool> stop_requested{false};
  std::uint64_t last_cycle = 0;
  std::thread loop([&] {
    for (std::uint64_t k = 0;; ++k) {
      if (!logger.TryLog(static_cast<double>(k) * 0.00025, std::array{static_cast<double>(k)})) {
        ADD_FAILURE() << "row dropped at cycle " << k;
      }
      last_cycle = k;
      if (stop_requested.load() && k >= 100) return;
      std::this_thread::sleep_for(std::chrono::microseconds(20));  // paced like a loop
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(12));
  stop_requested.store(true);
  loop.join();
  logger.Stop();
  logger.Stop();   // idempotent
  logger.Flush();  // no effect after Stop
  const auto rows = ReadRows(Path());
  ASSERT_EQ(rows.size(), last_cycle + 1);
  EXPECT_EQ(rows.back()[1], static_cast<double>(last_cycle));
  EXPECT_EQ(logger.rows_written(), last_cycle + 1);
  EXPECT_EQ(logger.rows_dropped(), 0U);
}

TEST_F(CsvLoggerTest, DestructorDrainsLikeStop) {
  {
    CsvLogger logger(Config(Path(), {"k"}));
    logger.Start();
    for (int k = 0; k < 100; ++k) ASSERT_TRUE(logger.TryLog(k, std::array{k * 2.0}));
  }
  EXPECT_EQ(ReadRows(Path()).size(), 100U);
}

TEST_F(CsvLoggerTest, FlushPutsQueuedRowsInTheFileWhileRunning) {
  auto config = Config(Path(), {"k"});
  config.writer_poll_period_ns = 1'000'000'000;  // the writer would otherwise sleep 1 s
  config.file_flush_period_ns = 1'000'000'000'000;
  CsvLogger logger(config);
  logger.Start();
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(logger.TryLog(k, std::array{1.0 * k}));
  logger.Flush();
  EXPECT_EQ(ReadRows(Path()).size(), 10U);
  EXPECT_EQ(logger.rows_written(), 10U);
  logger.Flush();  // idempotent
  ASSERT_TRUE(logger.TryLog(10, std::array{10.0}));
  logger.Flush();
  EXPECT_EQ(ReadRows(Path()).size(), 11U);
  logger.Stop();
}

TEST_F(CsvLoggerTest, WriterEventuallyWritesWithoutBeingAsked) {
  auto config = Config(Path(), {"k"});
  config.writer_poll_period_ns = 1'000'000;
  config.file_flush_period_ns = 0;
  CsvLogger logger(config);
  logger.Start();
  for (int k = 0; k < 5; ++k) ASSERT_TRUE(logger.TryLog(k, std::array{1.0 * k}));
  // Polling writer: generous bound for a loaded shared machine.
  for (int i = 0; i < 2000 && logger.rows_written() < 5; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(logger.rows_written(), 5U);
  for (int i = 0; i < 2000 && ReadRows(Path()).size() < 5; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(ReadRows(Path()).size(), 5U);
  logger.Stop();
}

// Producer and writer at full speed through a small queue (many wraps): the file holds
// exactly the rows TryLog accepted, in order; the rest are counted as dropped.
TEST_F(CsvLoggerTest, ConcurrentStressKeepsEveryAcceptedRowInOrder) {
  auto config = Config(Path(), {"seq", "twice"});
  config.queue_capacity_rows = 256;
  config.writer_poll_period_ns = 100'000;
  CsvLogger logger(config);
  logger.Start();
  std::vector<std::uint8_t> accepted(kStressRows, 0);
  std::uint64_t accepted_count = 0;
  for (std::uint64_t i = 0; i < kStressRows; ++i) {
    const double seq = static_cast<double>(i);
    if (logger.TryLog(seq * 1e-4, std::array{seq, 2.0 * seq})) {
      accepted[i] = 1;
      ++accepted_count;
    } else {
      std::this_thread::yield();  // let the writer catch up now and then
    }
  }
  logger.Stop();
  EXPECT_EQ(logger.rows_written(), accepted_count);
  EXPECT_EQ(logger.rows_dropped(), kStressRows - accepted_count);
  const auto rows = ReadRows(Path());
  ASSERT_EQ(rows.size(), accepted_count);
  std::size_t r = 0;
  std::uint64_t mismatches = 0;
  for (std::uint64_t i = 0; i < kStressRows; ++i) {
    if (accepted[i] == 0) continue;
    const double seq = static_cast<double>(i);
    if (rows[r][1] != seq || rows[r][2] != 2.0 * seq || rows[r][0] != seq * 1e-4) ++mismatches;
    ++r;
  }
  EXPECT_EQ(mismatches, 0U);
}

TEST_F(CsvLoggerTest, ConcurrentStressWithRetryLosesNothing) {
  auto config = Config(Path(), {"seq"});
  config.queue_capacity_rows = 64;
  config.writer_poll_period_ns = 50'000;
  CsvLogger logger(config);
  logger.Start();
  const std::uint64_t rows_to_send = kStressRows / 3;
  std::uint64_t refused = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < rows_to_send;) {
      if (logger.TryLog(static_cast<double>(i), std::array{static_cast<double>(i)})) {
        ++i;
      } else {
        ++refused;
        std::this_thread::yield();
      }
    }
  });
  producer.join();
  logger.Stop();
  EXPECT_EQ(logger.rows_written(), rows_to_send);
  EXPECT_EQ(logger.rows_dropped(), refused);
  const auto rows = ReadRows(Path());
  ASSERT_EQ(rows.size(), rows_to_send);
  std::uint64_t out_of_order = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i][1] != static_cast<double>(i)) ++out_of_order;
  }
  EXPECT_EQ(out_of_order, 0U);
}

TEST_F(CsvLoggerTest, WriterRunsAtSchedOther) {
  CsvLogger logger(Config(Path(), {"k"}));
  EXPECT_EQ(logger.writer_sched_policy(), -1);
  logger.Start();
  EXPECT_EQ(logger.writer_sched_policy(), SCHED_OTHER);
  logger.Stop();
}

TEST_F(CsvLoggerTest, WriterStartedFromFifoThreadIsDemotedToSchedOther) {
  CsvLogger logger(Config(Path(), {"k"}));
  int fifo_rc = -1;
  std::thread starter([&] {
    sched_param param{};
    param.sched_priority = 1;
    fifo_rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    if (fifo_rc == 0) logger.Start();
  });
  starter.join();
  if (fifo_rc != 0) GTEST_SKIP() << "SCHED_FIFO refused here (" << fifo_rc << "); cannot test";
  EXPECT_EQ(logger.writer_sched_policy(), SCHED_OTHER);
  logger.Stop();
}

TEST_F(CsvLoggerTest, StartTwiceOrAfterStopIsALogicError) {
  CsvLogger logger(Config(Path(), {"k"}));
  logger.Start();
  EXPECT_THROW(logger.Start(), std::logic_error);
  logger.Stop();
  EXPECT_THROW(logger.Start(), std::logic_error);
}

TEST_F(CsvLoggerTest, OpenErrorNamesThePathAndTheReason) {
  const std::string path = Path("missing_dir/log.csv");
  try {
    CsvLogger logger(Config(path, {"k"}));
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("the folder '" + Path("missing_dir") + "' does not exist; create it first"),
              std::string::npos)
        << what;
  }
}

TEST_F(CsvLoggerTest, HeaderWriteErrorIsReportedAtConstruction) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  try {
    CsvLogger logger(Config("/dev/full", {"k"}));
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("/dev/full"), std::string::npos) << what;
    EXPECT_NE(what.find("No space left on device"), std::string::npos) << what;
  }
}

TEST_F(CsvLoggerTest, RejectsBadConfiguration) {
  auto expect_invalid = [&](CsvLoggerConfig config, const std::string& needle) {
    try {
      CsvLogger logger(std::move(config));
      ADD_FAILURE() << "expected invalid_argument mentioning " << needle;
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
    }
  };
  expect_invalid(Config("", {"k"}), "empty log path");
  expect_invalid(Config(Path(), {"x y"}), "'x y'");
  expect_invalid(Config(Path(), {"a,b"}), "'a,b'");
  expect_invalid(Config(Path(), {"\"q\""}), "not a plain identifier");
  expect_invalid(Config(Path(), {"1st"}), "'1st'");
  expect_invalid(Config(Path(), {""}), "column 1");
  expect_invalid(Config(Path(), {"a", "a"}), "used twice");
  expect_invalid(Config(Path(), {"time_s"}), "used twice");
  expect_invalid(Config(Path(), std::vector<std::string>(kMaxLogColumns + 1, "c")), "at most");
  auto config = Config(Path(), {"k"});
  config.queue_capacity_rows = 1000;
  expect_invalid(config, "power of two");
  config = Config(Path(), {"k"});
  config.decimation = 0;
  expect_invalid(config, "decimation");
  config = Config(Path(), {"k"});
  config.writer_poll_period_ns = 0;
  expect_invalid(config, "writer_poll_period_ns");
  config = Config(Path(), {"k"});
  config.writer_cpus = {-1};
  expect_invalid(config, "writer CPU -1");
}

TEST_F(CsvLoggerTest, MaxColumnsAndNoColumnsBothWork) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < kMaxLogColumns; ++i) names.push_back("c" + std::to_string(i));
  std::vector<double> values(kMaxLogColumns, -1.2345678901234567e-300);
  {
    CsvLogger wide(Config(Path("wide.csv"), names));
    ASSERT_TRUE(wide.TryLog(-1.2345678901234567e-300, values));
    CsvLogger narrow(Config(Path("narrow.csv"), {}));
    ASSERT_TRUE(narrow.TryLog(2.5, {}));
  }
  const auto wide_rows = ReadRows(Path("wide.csv"));
  ASSERT_EQ(wide_rows.size(), 1U);
  ASSERT_EQ(wide_rows[0].size(), kMaxLogColumns + 1);
  EXPECT_EQ(wide_rows[0][kMaxLogColumns], -1.2345678901234567e-300);
  const auto narrow_lines = ReadLines(Path("narrow.csv"));
  ASSERT_EQ(narrow_lines.size(), 2U);
  EXPECT_EQ(narrow_lines[0], "time_s");
  EXPECT_EQ(narrow_lines[1], "2.5");
}

TEST_F(CsvLoggerTest, WriterCanBePinnedToACpu) {
  auto config = Config(Path(), {"k"});
  cpu_set_t allowed;
  ASSERT_EQ(sched_getaffinity(0, sizeof allowed, &allowed), 0);
  int first_cpu = 0;
  while (!CPU_ISSET(static_cast<std::size_t>(first_cpu), &allowed)) ++first_cpu;
  config.writer_cpus = {first_cpu};
  CsvLogger logger(config);
  logger.Start();
  ASSERT_TRUE(logger.TryLog(0.0, std::array{1.0}));
  logger.Stop();
  EXPECT_EQ(logger.rows_written(), 1U);
}

}  // namespace
}  // namespace hiltwin::tracing
