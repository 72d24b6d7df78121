#pragma once
/// Real-time-safe CSV data logger: the loop offers rows with TryLog (no allocation, no lock,
/// no system call), a non-real-time writer thread drains a lock-free queue to the file.
///
/// File format (DESIGN.md "Logs"): a header row `time_s,<column>,...`, then one row per logged
/// cycle, plain comma-separated, numbers in the shortest form that parses back to the same
/// double (std::to_chars), non-finite values as NaN/Inf/-Inf. 20-sim's DataFromFile and
/// MATLAB's readmatrix/readtable read it directly.

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/tracing/spsc_ring.h"

namespace hiltwin::tracing {

/// Most value columns a logger accepts (time_s not counted); bounds the writer's line buffer.
inline constexpr std::size_t kMaxLogColumns = 32;

/// Logger set-up, fixed before the run.
struct CsvLoggerConfig {
  std::string path;                                 ///< output file, truncated at construction
  std::vector<std::string> columns;                 ///< value column names after "time_s"
  /// Lines written before the header row, each as "# <line>" (CSV readers that take '#'
  /// comments skip them): a file's format and fixed facts, e.g. the timing log's.
  std::vector<std::string> preamble;
  std::size_t queue_capacity_rows = 1 << 16;        ///< power of two; 65536 rows = 16 s at 4 kHz
  std::uint32_t decimation = 1;                     ///< log every Nth offered row (1 = all)
  std::int64_t writer_poll_period_ns = 2'000'000;   ///< writer sleeps this long between drains
  std::int64_t file_flush_period_ns = 100'000'000;  ///< writer hands data to the OS this often
  std::vector<int> writer_cpus;  ///< CPUs for the writer thread; empty = every allowed CPU
  /// Off-line runs only (virtual clock): when the queue is full the producer waits for the
  /// started writer instead of dropping, so an as-fast-as-possible run logs every row. Never
  /// set this for a real-time loop: it makes TryLog block.
  bool wait_when_full = false;
};

/// Single-producer CSV logger. One thread (the loop) calls TryLog; one control thread calls
/// Start, Flush and Stop (may be the same thread, outside its real-time section).
class CsvLogger {
 public:
  /// Validates the config and opens the file; throws std::invalid_argument (bad config) or
  /// std::runtime_error (open/write failure, with path and errno text). Writes the header.
  explicit CsvLogger(CsvLoggerConfig config);
  /// Stops (drains and closes) if still running.
  ~CsvLogger();
  CsvLogger(const CsvLogger&) = delete;
  CsvLogger& operator=(const CsvLogger&) = delete;

  /// Starts the writer thread `hiltwin-log` at SCHED_OTHER on writer_cpus. Throws std::logic_error if called twice or
  /// after Stop, std::system_error if the thread cannot be created.
  void Start();

  /// Producer (RT-safe): offers one row. Every `decimation`-th offer is queued. Returns false
  /// only when a row that should be logged is lost: queue full, logger stopped, or
  /// values.size() differs from the column count; each such row counts in rows_dropped().
  bool TryLog(double time_s, std::span<const double> values) noexcept;

  /// Writes every row queued before the call and hands it to the OS (fflush). Blocks the
  /// calling (non-RT) thread until done. Idempotent; no effect after Stop.
  void Flush();

  /// Drains every queued row, flushes and closes the file, joins the writer. Idempotent.
  /// Call after the producer's last TryLog (e.g. after the loop has stopped).
  void Stop();

  /// Rows handed to the file (header not counted).
  [[nodiscard]] std::uint64_t rows_written() const noexcept;
  /// Rows lost: queue full, offered after Stop, wrong width, or failed to write.
  [[nodiscard]] std::uint64_t rows_dropped() const noexcept;
  /// TryLog calls, decimated ones included.
  [[nodiscard]] std::uint64_t rows_offered() const noexcept;
  /// Empty while all is well; otherwise the first write error (path and errno text).
  [[nodiscard]] std::string error() const;
  /// Scheduling policy the writer thread runs at (SCHED_OTHER), or -1 before Start.
  [[nodiscard]] int writer_sched_policy() const noexcept;
  /// The file path.
  [[nodiscard]] const std::string& path() const noexcept { return config_.path; }
  /// Value column count (time_s not counted).
  [[nodiscard]] std::size_t column_count() const noexcept { return config_.columns.size(); }

 private:
  void WriterMain();
  void ConfigureWriterThread();
  void DrainAvailable();
  void FlushFile();
  void RecordIoError(const char* what, int err);

  CsvLoggerConfig config_;
  std::size_t row_stride_;  ///< doubles per queued row: time + columns

  // Producer side. Counters are written by the producer only (plain load+store, no RMW) and
  // read by anyone.
  SpscRing ring_;
  std::unique_ptr<double[]> rows_;
  std::uint32_t decimation_countdown_ = 0;
  std::atomic<std::uint64_t> offered_{0};
  std::atomic<std::uint64_t> producer_dropped_{0};
  std::atomic<bool> accepting_{true};

  // Consumer side: the writer thread while it runs, otherwise the control thread.
  std::FILE* file_ = nullptr;
  std::unique_ptr<char[]> file_buffer_;
  std::array<char, (kMaxLogColumns + 1) * 32 + 2> line_{};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> write_failed_{0};
  std::int64_t last_flush_ns_ = 0;

  // Control.
  mutable std::mutex mutex_;
  std::condition_variable wake_writer_;
  std::condition_variable writer_done_;
  bool started_ = false;
  bool stopped_ = false;
  bool writer_ready_ = false;
  std::atomic<bool> writer_ready_for_producer_{false};  ///< wait_when_full may wait on it
  bool stop_requested_ = false;
  std::uint64_t flush_requested_ = 0;
  std::uint64_t flush_completed_ = 0;
  std::string error_;
  std::atomic<int> writer_policy_{-1};
  kernel_glue::NamedThread writer_;
};

}  // namespace hiltwin::tracing
