// Producer cost of logging one row from the loop: hiltwin's CsvLogger::TryLog against the
// usual alternative, an spdlog asynchronous file logger formatting the same row (spdlog
// formats in the caller, then queues). Rows are offered in bursts of kBurstRows, the queue is
// drained between bursts, and only the offering is timed, so both measure their accepted
// path rather than a full queue. Also: the writer's drain rate and the cost of a compiled-in
// but not recording HILTWIN_TRACE. Then instructions per row (callgrind, load-independent)
// of the writer (format + write(2), the work of the `hiltwin-log` thread) and of the producer
// (TryLog), for the twin's 15-column row (time + 14 values, shaped as the default RELbot run's).
//
// Usage: hiltwin_bench_logger [bursts]   (default 200 bursts of 4096 rows, 8 value columns)
//        hiltwin_bench_logger --count writer|producer ROWS   (one bracket, for callgrind)
#include <spdlog/async.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "callgrind_count.h"
#include "hiltwin/tracing/csv_logger.h"
#include "hiltwin/tracing/trace.h"

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kBurstRows = 4096;
constexpr std::size_t kColumns = 8;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

double NsPerCall(Clock::time_point start, Clock::time_point end, int calls) {
  return static_cast<double>(
             std::chrono::duration_cast<std::chrono::nanoseconds>(end - start).count()) /
         calls;
}

std::array<double, kColumns> Row(int k) {
  std::array<double, kColumns> row{};
  for (std::size_t c = 0; c < kColumns; ++c)
    row[c] = 0.001 * k + 0.1234567 * static_cast<double>(c);
  return row;
}

// Producer cost per row of each burst, and what the queue dropped.
struct ProducerCost {
  std::vector<double> ns_per_row;
  std::uint64_t dropped = 0;
};

ProducerCost MeasureCsvLogger(int bursts, const std::filesystem::path& dir,
                              const std::vector<std::string>& names) {
  ProducerCost cost;
  hiltwin::tracing::CsvLoggerConfig config;
  config.path = (dir / "ours.csv").string();
  config.columns = names;
  hiltwin::tracing::CsvLogger logger(config);
  logger.Start();
  int k = 0;
  for (int b = 0; b < bursts; ++b) {
    const auto start = Clock::now();
    for (int i = 0; i < kBurstRows; ++i, ++k) {
      const auto row = Row(k);
      logger.TryLog(k * 0.00025, row);
    }
    const auto end = Clock::now();
    cost.ns_per_row.push_back(NsPerCall(start, end, kBurstRows));
    logger.Flush();
  }
  logger.Stop();
  cost.dropped = logger.rows_dropped();
  return cost;
}

// Peer: spdlog async logger, same row, "{},{},..." with the same shortest-round-trip
// formatting fmt uses by default for doubles.
std::vector<double> MeasureSpdlog(int bursts, const std::filesystem::path& dir) {
  std::vector<double> peer;
  spdlog::init_thread_pool(1 << 16, 1);
  auto logger =
      spdlog::basic_logger_mt<spdlog::async_factory>("peer", (dir / "peer.csv").string(), true);
  logger->set_pattern("%v");
  int k = 0;
  for (int b = 0; b < bursts; ++b) {
    const auto start = Clock::now();
    for (int i = 0; i < kBurstRows; ++i, ++k) {
      const auto r = Row(k);
      logger->info("{},{},{},{},{},{},{},{},{}", k * 0.00025, r[0], r[1], r[2], r[3], r[4], r[5],
                   r[6], r[7]);
    }
    const auto end = Clock::now();
    peer.push_back(NsPerCall(start, end, kBurstRows));
    while (spdlog::thread_pool()->queue_size() != 0)
      std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  spdlog::shutdown();
  return peer;
}

// Writer drain rate: a full queue formatted and written by Stop.
double MeasureDrainRowsPerS(const std::filesystem::path& dir,
                            const std::vector<std::string>& names) {
  hiltwin::tracing::CsvLoggerConfig config;
  config.path = (dir / "drain.csv").string();
  config.columns = names;
  hiltwin::tracing::CsvLogger logger(config);
  const int rows = static_cast<int>(config.queue_capacity_rows);
  for (int k = 0; k < rows; ++k) logger.TryLog(k * 0.00025, Row(k));
  const auto start = Clock::now();
  logger.Stop();
  const auto end = Clock::now();
  return rows / std::chrono::duration<double>(end - start).count();
}

// The RELbot twin's log row (relbot: PlantTwinTask::LogColumns + CycleRunner's timing).
const std::vector<std::string> kTwinColumns = {
    "duty_left", "duty_right", "wheel_left_m", "wheel_right_m", "x_m", "y_m", "theta_rad",
    "enc_left", "enc_right", "cycle", "latency_us", "compute_us", "io_us", "missed"};
constexpr double kTwinPeriodS = 0.00025;
constexpr std::size_t kTwinValues = 14;

// Row k of a turning RELbot at 4 kHz, cell by cell of the kind the default 60 s run logs (in
// 78 % of its rows the robot turns): the time k * h (exact to 6 decimals in most rows), duties
// in steps of 1/2048 held for a second, five full-precision states, encoder counts and the
// cycle as whole numbers, and the timing columns a virtual-clock run leaves at 0.
std::array<double, kTwinValues> TwinRow(std::int64_t k) {
  const double t = static_cast<double>(k) * kTwinPeriodS;
  const double duty_left = static_cast<double>((k / 4000) % 1639 - 819) / 2048.0;
  const double duty_right = static_cast<double>((k / 4000 + 7) % 1639 - 819) / 2048.0;
  const double left = 0.4 * t + 0.05 * std::sin(0.7 * t);
  const double right = 0.4 * t + 0.05 * std::cos(0.3 * t);
  const double theta = (right - left) / 0.209;
  return {duty_left,
          duty_right,
          left,
          right,
          0.5 * (left + right) * std::cos(theta),
          0.5 * (left + right) * std::sin(theta),
          theta,
          std::round(left * 12'732.0),
          std::round(right * 12'732.0),
          static_cast<double>(k),
          0.0,
          0.0,
          0.0,
          0.0};
}

std::size_t PowerOfTwoAtLeast(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p *= 2;
  return p;
}

// `--count writer|producer ROWS`: ROWS twin rows, only the measured half between two
// ToggleCounting() calls. The writer's half is Flush on a logger that was not started: the
// calling thread drains the queue (format) and writes the file, as the writer thread does.
int CountedRows(const char* what, const char* rows_text, const std::filesystem::path& dir) {
  const long rows = std::atol(rows_text);
  const bool writer = std::strcmp(what, "writer") == 0;
  if (rows <= 0 || (!writer && std::strcmp(what, "producer") != 0)) {
    std::fprintf(stderr, "usage: hiltwin_bench_logger --count writer|producer ROWS(>0)\n");
    return 2;
  }
  std::vector<std::array<double, kTwinValues>> values;
  for (long k = 0; k < rows; ++k) values.push_back(TwinRow(k + 1));
  hiltwin::tracing::CsvLoggerConfig config;
  config.path = (dir / "count.csv").string();
  config.columns = kTwinColumns;
  config.queue_capacity_rows = PowerOfTwoAtLeast(static_cast<std::size_t>(rows));
  hiltwin::tracing::CsvLogger logger(config);
  if (!writer) hiltwin::bench::ToggleCounting();
  for (long k = 0; k < rows; ++k) {
    logger.TryLog(static_cast<double>(k + 1) * kTwinPeriodS, values[static_cast<std::size_t>(k)]);
  }
  if (!writer) hiltwin::bench::ToggleCounting();
  if (writer) hiltwin::bench::ToggleCounting();
  logger.Flush();
  if (writer) hiltwin::bench::ToggleCounting();
  logger.Stop();
  return logger.rows_written() == static_cast<std::uint64_t>(rows) ? 0 : 3;
}

// Instructions per row: two row counts under callgrind, so set-up and the first write cancel.
void ReportRowInstructions(const char* self) {
  constexpr std::uint64_t kFew = 4'000;
  constexpr std::uint64_t kMany = 24'000;
  double per_row[2] = {};
  for (const bool writer : {true, false}) {
    const auto count = [&](std::uint64_t rows) {
      return hiltwin::bench::CountInstructions(
          {self, "--count", writer ? "writer" : "producer", std::to_string(rows)});
    };
    per_row[writer ? 0 : 1] =
        hiltwin::bench::InstructionsPerItem(kFew, count(kFew), kMany, count(kMany));
  }
  std::printf("instructions per 15-column twin row (callgrind, %llu against %llu rows):\n",
              static_cast<unsigned long long>(kMany), static_cast<unsigned long long>(kFew));
  std::printf("  writer (format + write)     %6.0f   target <= 2500: %s\n", per_row[0],
              per_row[0] <= 2500.0 ? "met" : "NOT met");
  std::printf("  producer (TryLog)           %6.0f\n", per_row[1]);
}

// A compiled-in tracepoint with no session recording (one branch).
double MeasureIdleTraceNs() {
  constexpr int kCalls = 10'000'000;
  const auto start = Clock::now();
  for (int k = 0; k < kCalls; ++k) {
    const auto k64 = static_cast<std::uint64_t>(k);
    const auto t = static_cast<std::int64_t>(k);
    HILTWIN_TRACE(cycle, k64, t, t + 1, t + 2, t + 3, std::int64_t{0}, std::uint32_t{0},
                  std::uint8_t{0}, std::uint8_t{1});
    asm volatile("" ::: "memory");
  }
  return NsPerCall(start, Clock::now(), kCalls);
}

}  // namespace

int main(int argc, char** argv) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("hiltwin_bench_logger_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  if (argc == 4 && std::strcmp(argv[1], "--count") == 0) {
    const int status = CountedRows(argv[2], argv[3], dir);
    std::filesystem::remove_all(dir);
    return status;
  }
  const int bursts = argc > 1 ? std::atoi(argv[1]) : 200;
  std::vector<std::string> names;
  for (std::size_t c = 0; c < kColumns; ++c) names.push_back("v" + std::to_string(c));

  const ProducerCost ours = MeasureCsvLogger(bursts, dir, names);
  const std::vector<double> peer = MeasureSpdlog(bursts, dir);
  const double drain_rows_per_s = MeasureDrainRowsPerS(dir, names);
  const double trace_ns = MeasureIdleTraceNs();

  std::filesystem::remove_all(dir);
  const double ours_ns = Median(ours.ns_per_row);
  const double peer_ns = Median(peer);
  std::printf("rows: %d bursts x %d rows, time + %zu columns\n", bursts, kBurstRows, kColumns);
  std::printf("hiltwin CsvLogger::TryLog     median %.1f ns/row (dropped %llu)\n", ours_ns,
              static_cast<unsigned long long>(ours.dropped));
  std::printf("peer spdlog async info(...)   median %.1f ns/row\n", peer_ns);
  std::printf("ratio hiltwin/peer            %.3f\n", ours_ns / peer_ns);
  std::printf("writer drain (format+write)   %.0f rows/s\n", drain_rows_per_s);
  std::printf("HILTWIN_TRACE(cycle) idle     %.2f ns/call (LTTng %s)\n", trace_ns,
              hiltwin::tracing::kTracingCompiledIn ? "compiled in, no session" : "compiled out");
  try {
    ReportRowInstructions(argv[0]);
  } catch (const std::exception& e) {  // no valgrind: the time figures above stand alone
    std::printf("instructions per row: not counted (%s)\n", e.what());
  }
  return 0;
}
