#pragma once
/// Real-time-safe CSV data logger: the loop offers rows with TryLog (no allocation, no lock,
/// no system call), a non-real-time writer thread drains a lock-free queue to the file.
///
/// File format (docs/architecture.md "Logs", docs/logs.md): a header row `time_s,<column>,...`,
/// then one row per logged cycle, plain comma-separated, numbers in the shortest form that parses
/// back to the same double (std::to_chars), non-finite values as NaN/Inf/-Inf. 20-sim's
/// DataFromFile and MATLAB's readmatrix/readtable read it directly.
///
/// Accounting (an invariant the tests hold it to): every row the decimation selects ends as
/// exactly one of written (its bytes were accepted by the kernel: it is in the file), dropped
/// (the queue was full, the logger had stopped, or the row had the wrong width) or lost (the
/// file could not take it: disk full, file-size limit, I/O error), so after Stop
/// rows_written() + rows_dropped() + rows_lost() == rows_selected().
///
/// A failed or short write (ENOSPC, EFBIG, EIO, ...) ends the log: the file is cut back to the
/// end of its last whole row, so every line in it parses, and nothing more is written. The
/// writer does not retry later rows: a log that resumed after freed space would have a gap a
/// reader cannot see. Every row after the failure counts as lost, and error() says why.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/lockfree/spsc_ring.h"

namespace hiltwin::tracing {
namespace detail {
struct CellMemo;
}  // namespace detail

/// The log's file cannot be written at all (its header failed: a full disk, an I/O error):
/// the disk's problem, not the path's.
class LogWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Most value columns a logger accepts (time_s not counted); bounds the writer's line buffer.
inline constexpr std::size_t kMaxLogColumns = 32;

/// Logger set-up, fixed before the run.
struct CsvLoggerConfig {
  /// Output file, created or truncated at construction; a symbolic link is refused
  /// (kernel_glue::OpenOutputFile), so a log never lands where the user did not name.
  std::string path;
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
  /// Validates the config and opens the file; throws std::invalid_argument (bad config),
  /// kernel_glue::OutputFileError (the path cannot be opened: a link, a missing folder, ...) or
  /// LogWriteError (the header cannot be written, with path and errno text). Writes the
  /// header.
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

  /// Writes every row queued before the call to the file (write(2)). Blocks the calling
  /// (non-RT) thread until done. Idempotent; no effect after Stop.
  void Flush();

  /// Drains every queued row, flushes and closes the file, joins the writer. Idempotent.
  /// Call after the producer's last TryLog (e.g. after the loop has stopped).
  void Stop();

  /// Rows in the file: their bytes were accepted by write(2) (header not counted).
  [[nodiscard]] std::uint64_t rows_written() const noexcept;
  /// Rows that never reached the writer: queue full, offered after Stop, or wrong width.
  [[nodiscard]] std::uint64_t rows_dropped() const noexcept;
  /// Rows the writer had but the file did not take: those of a failed or short write that did
  /// not reach the file whole, and every row after it.
  [[nodiscard]] std::uint64_t rows_lost() const noexcept;
  /// Rows the decimation selected (should have been logged); after Stop equals
  /// rows_written() + rows_dropped() + rows_lost().
  [[nodiscard]] std::uint64_t rows_selected() const noexcept;
  /// TryLog calls, decimated ones included.
  [[nodiscard]] std::uint64_t rows_offered() const noexcept;
  /// Empty while all is well; otherwise the first write error (path and errno text).
  [[nodiscard]] std::string error() const;
  /// The errno text of the first write error alone ("No space left on device"), or empty.
  [[nodiscard]] std::string error_reason() const;
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
  void WriteBuffer();
  void EndAfterFailedWrite(std::size_t accepted_bytes, int err);
  void RecordIoError(const char* what, int err, const std::string& note = {});

  CsvLoggerConfig config_;
  std::size_t row_stride_;  ///< doubles per queued row: time + columns

  // Producer side. Counters are written by the producer only (plain load+store, no RMW) and
  // read by anyone.
  lockfree::SpscRing ring_;
  std::unique_ptr<double[]> row_storage_;
  double* rows_;  ///< row_storage_ from its first cache-line boundary
  std::uint32_t decimation_countdown_ = 0;
  std::atomic<std::uint64_t> offered_{0};
  std::atomic<std::uint64_t> producer_dropped_{0};
  std::atomic<bool> accepting_{true};

  // Consumer side: the writer thread while it runs, otherwise the control thread.
  // Rows are formatted straight into file_buffer_ and handed to the kernel with write(2), so
  // the logger knows which rows reached the file (stdio would accept a row into its buffer
  // and fail later, in fflush, for rows already counted).
  int fd_ = -1;
  std::unique_ptr<detail::CellMemo[]> cell_memos_;  ///< each column's last text
  std::unique_ptr<char[]> file_buffer_;
  std::size_t buffered_bytes_ = 0;       ///< formatted, not yet written
  std::uint64_t buffered_rows_ = 0;      ///< whole rows in those bytes
  std::uint64_t file_bytes_ = 0;         ///< bytes in the file, always at a row boundary
  bool write_failed_ = false;            ///< a write failed: the log has ended
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> lost_{0};
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
  std::string error_reason_;
  std::atomic<int> writer_policy_{-1};
  kernel_glue::NamedThread writer_;
};

}  // namespace hiltwin::tracing
