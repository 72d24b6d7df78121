// Producer cost of logging one row from the loop: hiltwin's CsvLogger::TryLog against the
// usual alternative, an spdlog asynchronous file logger formatting the same row (spdlog
// formats in the caller, then queues). Rows are offered in bursts of kBurstRows, the queue is
// drained between bursts, and only the offering is timed, so both measure their accepted
// path rather than a full queue. Also: the writer's drain rate and the cost of a compiled-in
// but not recording HILTWIN_TRACE.
//
// Usage: hiltwin_bench_logger [bursts]   (default 200 bursts of 4096 rows, 8 value columns)
#include <spdlog/async.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

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
  const int bursts = argc > 1 ? std::atoi(argv[1]) : 200;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("hiltwin_bench_logger_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
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
  return 0;
}
