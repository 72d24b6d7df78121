#include "hiltwin/tracing/csv_logger.h"

#include <thread>

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "hiltwin/kernel_glue/output_file.h"
#include "log_number.h"

namespace hiltwin::tracing {
namespace {

// Large enough that the writer makes one write() per few hundred rows, small enough to stay
// out of the way of the loop's locked memory budget.
constexpr std::size_t kFileBufferBytes = std::size_t{256} * 1024;
// Room for the longest row: a cell is at most detail::kMaxNumberChars = 24 characters (the
// shortest double; the fixed-point shortcuts print fewer) plus its comma, rounded up to 32,
// and the newline. The buffer is written out before a row might not fit.
constexpr std::size_t kMaxLineBytes = (kMaxLogColumns + 1) * 32 + 2;
static_assert((kMaxLogColumns + 1) * (detail::kMaxNumberChars + 1) + detail::kNumberScratchChars <=
                  kMaxLineBytes,
              "the widest row and the scratch its last cell may write fit in kMaxLineBytes");
// Keeps the preallocated queue below ~8 GiB even at the widest row; a larger request is a
// typo, not a plan.
constexpr std::size_t kMaxQueueCapacityRows = std::size_t{1} << 24;
// MATLAB's namelengthmax: longer names would be truncated by readtable.
constexpr std::size_t kMaxColumnNameChars = 63;
// Rows the writer formats before it hands their slots back (DrainAvailable): 8 KiB of a
// 15-column row, 1/1024 of the default queue.
constexpr std::size_t kReleaseBatchRows = 64;
// The queue's rows start on a cache line, so a 16-double row is exactly two lines and the
// producer's row never shares a line with the one the writer reads.
constexpr std::size_t kRowAlignment = 64;

std::string ErrnoText(int err) {
  // strerror is not thread-safe in theory; this runs on set-up and error paths only, and the
  // GNU strerror_r form returns a pointer that may or may not be the buffer.
  char buffer[256];
  const char* text = strerror_r(err, buffer, sizeof buffer);
  return text;
}

bool IsPlainIdentifier(const std::string& name) {
  if (name.empty()) return false;
  const auto is_alpha = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); };
  const auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  if (!is_alpha(name.front())) return false;
  return std::all_of(name.begin(), name.end(),
                     [&](char c) { return is_alpha(c) || is_digit(c) || c == '_'; });
}

CsvLoggerConfig Validate(CsvLoggerConfig config) {
  const std::string where = "CsvLogger('" + config.path + "'): ";
  if (config.path.empty()) {
    throw std::invalid_argument("CsvLogger: empty log path; pass a file name such as run.csv");
  }
  if (config.columns.size() > kMaxLogColumns) {
    throw std::invalid_argument(where + std::to_string(config.columns.size()) +
                                " columns requested, at most " + std::to_string(kMaxLogColumns) +
                                " supported; log fewer signals");
  }
  std::set<std::string> seen{"time_s"};
  for (std::size_t i = 0; i < config.columns.size(); ++i) {
    const std::string& name = config.columns[i];
    if (!IsPlainIdentifier(name) || name.size() > kMaxColumnNameChars) {
      throw std::invalid_argument(
          where + "column " + std::to_string(i + 1) + " name '" + name +
          "' is not a plain identifier ([A-Za-z][A-Za-z0-9_]*, at most 63 characters) that "
          "MATLAB and 20-sim read without quoting; rename it, e.g. wheel_left_m");
    }
    if (!seen.insert(name).second) {
      throw std::invalid_argument(where + "column " + std::to_string(i + 1) + " name '" + name +
                                  "' is used twice (time_s is reserved); make names unique");
    }
  }
  for (const std::string& line : config.preamble) {
    if (line.find_first_of("\r\n") != std::string::npos) {
      throw std::invalid_argument(where + "preamble line '" + line +
                                  "' holds a line break; give one line per entry");
    }
  }
  const std::size_t capacity = config.queue_capacity_rows;
  if (capacity == 0 || (capacity & (capacity - 1)) != 0 || capacity > kMaxQueueCapacityRows) {
    throw std::invalid_argument(where + "queue_capacity_rows " + std::to_string(capacity) +
                                " must be a power of two between 1 and " +
                                std::to_string(kMaxQueueCapacityRows) + ", e.g. 65536");
  }
  if (config.decimation == 0) {
    throw std::invalid_argument(where + "decimation 0; use 1 to log every cycle, N for every Nth");
  }
  if (config.writer_poll_period_ns <= 0) {
    throw std::invalid_argument(where + "writer_poll_period_ns must be positive, e.g. 2000000");
  }
  if (config.file_flush_period_ns < 0) {
    throw std::invalid_argument(where + "file_flush_period_ns must be >= 0 (0 = every drain)");
  }
  for (const int cpu : config.writer_cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE) {
      throw std::invalid_argument(where + "writer CPU " + std::to_string(cpu) +
                                  " out of range; list CPUs from 0 to " +
                                  std::to_string(CPU_SETSIZE - 1));
    }
  }
  return config;
}

std::int64_t SteadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// write(2) until all of `data` is accepted or the kernel refuses more: the bytes accepted and
/// the errno that stopped it (0 when all were). A write that accepts nothing without an error
/// counts as EIO, so the loop always ends.
std::pair<std::size_t, int> WriteAll(int fd, const char* data, std::size_t size) noexcept {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      return {done, n < 0 ? errno : EIO};
    }
  }
  return {done, 0};
}

/// The first cache-line boundary in `storage` (which has kRowAlignment bytes to spare).
double* AlignedRows(double* storage) noexcept {
  void* start = storage;
  std::size_t space = kRowAlignment;
  return static_cast<double*>(std::align(kRowAlignment, sizeof(double), start, space));
}

}  // namespace

CsvLogger::CsvLogger(CsvLoggerConfig config)
    : config_(Validate(std::move(config))),
      row_stride_(1 + config_.columns.size()),
      ring_(config_.queue_capacity_rows),
      // Value-initialised, so every page is touched now rather than in the loop.
      row_storage_(std::make_unique<double[]>(config_.queue_capacity_rows * row_stride_ +
                                              kRowAlignment / sizeof(double))),
      rows_(AlignedRows(row_storage_.get())),
      cell_memos_(std::make_unique<detail::CellMemo[]>(row_stride_)),
      file_buffer_(std::make_unique<char[]>(kFileBufferBytes)) {
  fd_ = kernel_glue::OpenOutputFile(config_.path, "the log file");
  std::string header;
  for (const std::string& line : config_.preamble) header.append("# ").append(line).append("\n");
  header += "time_s";
  for (const std::string& name : config_.columns) header.append(",").append(name);
  header += "\n";
  const auto [accepted, err] = WriteAll(fd_, header.data(), header.size());
  if (err != 0) {
    (void)::ftruncate(fd_, 0);  // no torn header: an empty file is plainly unfinished
    ::close(fd_);
    fd_ = -1;
    throw LogWriteError("CsvLogger: cannot write the header of '" + config_.path + "': " +
                        ErrnoText(err) + "; free space or choose another folder");
  }
  file_bytes_ = accepted;
  last_flush_ns_ = SteadyNowNs();
}

CsvLogger::~CsvLogger() {
  try {
    Stop();
  } catch (...) {
    // A destructor must not throw; Stop only throws if joining the thread fails.
  }
}

void CsvLogger::Start() {
  std::unique_lock lock(mutex_);
  if (started_) throw std::logic_error("CsvLogger::Start called twice for '" + config_.path + "'");
  if (stopped_) throw std::logic_error("CsvLogger::Start after Stop for '" + config_.path + "'");
  writer_ready_ = false;
  try {
    writer_ = kernel_glue::NamedThread({"hiltwin-log", config_.writer_cpus}, [this] { WriterMain(); });
  } catch (const std::exception& e) {
    throw std::runtime_error("CsvLogger: writer thread for '" + config_.path + "': " + e.what());
  }
  writer_done_.wait(lock, [this] { return writer_ready_; });
  started_ = true;
  writer_ready_for_producer_.store(true, std::memory_order_release);
}

bool CsvLogger::TryLog(double time_s, std::span<const double> values) noexcept {
  offered_.store(offered_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (decimation_countdown_ != 0) {
    --decimation_countdown_;
    return true;
  }
  decimation_countdown_ = config_.decimation - 1;
  std::size_t slot = 0;
  bool claimed = accepting_.load(std::memory_order_relaxed) && values.size() + 1 == row_stride_ &&
                 ring_.TryClaim(slot);
  if (!claimed && config_.wait_when_full && writer_ready_for_producer_.load(std::memory_order_acquire)) {
    // Off-line mode: give the writer the CPU until it has made room (or the logger stops).
    while (!claimed && accepting_.load(std::memory_order_relaxed) && values.size() + 1 == row_stride_) {
      std::this_thread::yield();
      claimed = ring_.TryClaim(slot);
    }
  }
  if (!claimed) {
    producer_dropped_.store(producer_dropped_.load(std::memory_order_relaxed) + 1,
                            std::memory_order_relaxed);
    return false;
  }
  double* row = rows_ + slot * row_stride_;
  row[0] = time_s;
  std::copy(values.begin(), values.end(), row + 1);
  ring_.Publish();
  return true;
}

void CsvLogger::Flush() {
  std::unique_lock lock(mutex_);
  if (stopped_) return;
  if (started_) {
    const std::uint64_t target = ++flush_requested_;
    wake_writer_.notify_all();
    writer_done_.wait(lock, [&] { return flush_completed_ >= target; });
    return;
  }
  lock.unlock();
  DrainAvailable();
  WriteBuffer();
}

void CsvLogger::Stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopped_) return;
    stopped_ = true;
    stop_requested_ = true;
  }
  accepting_.store(false, std::memory_order_relaxed);
  if (writer_.joinable()) {
    wake_writer_.notify_all();
    writer_.Join();
  }
  // The writer drained after seeing the stop request; this catches a writer that never ran.
  DrainAvailable();
  if (fd_ >= 0) {
    WriteBuffer();
    // A close error (a network file system's delayed write) comes too late to say which rows
    // are missing: the log is reported incomplete, the counts are those of the writes.
    if (::close(fd_) != 0) RecordIoError("close", errno);
    fd_ = -1;
  }
}

void CsvLogger::WriterMain() {
  ConfigureWriterThread();
  std::unique_lock lock(mutex_);
  writer_ready_ = true;
  writer_done_.notify_all();
  const auto poll_period = std::chrono::nanoseconds(config_.writer_poll_period_ns);
  for (;;) {
    const bool stop = stop_requested_;
    const std::uint64_t flush_target = flush_requested_;
    lock.unlock();
    DrainAvailable();
    const std::int64_t now_ns = SteadyNowNs();
    if (stop || flush_target != flush_completed_ ||
        now_ns - last_flush_ns_ >= config_.file_flush_period_ns) {
      WriteBuffer();
      last_flush_ns_ = now_ns;
    }
    lock.lock();
    flush_completed_ = flush_target;
    writer_done_.notify_all();
    if (stop) return;
    // The producer never signals (no syscall per row); control requests cut the sleep short.
    wake_writer_.wait_for(lock, poll_period,
                          [&] { return stop_requested_ || flush_requested_ != flush_target; });
  }
}

void CsvLogger::ConfigureWriterThread() {
  // The thread was created at SCHED_OTHER on writer_cpus (kernel_glue::NamedThread), whatever
  // the policy of the thread that started it; record what it runs at for the report and tests.
  int policy = -1;
  sched_param actual{};
  if (pthread_getschedparam(pthread_self(), &policy, &actual) == 0) {
    writer_policy_.store(policy, std::memory_order_relaxed);
  }
}

void CsvLogger::DrainAvailable() {
  std::size_t available = ring_.Available();
  while (available != 0) {
    // Slots go back to the producer a batch at a time: one store to the shared index per batch
    // rather than per row, and a waiting producer (wait_when_full) refills a batch's worth of
    // rows away from the ones being read instead of the row next to them.
    const std::size_t batch = std::min(available, kReleaseBatchRows);
    for (std::size_t r = 0; r < batch; ++r) {
      if (!write_failed_ && kFileBufferBytes - buffered_bytes_ < kMaxLineBytes) WriteBuffer();
      if (write_failed_ || fd_ < 0) {
        // The log has ended (see the header): the row is counted, not written.
        lost_.store(lost_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        continue;
      }
      const double* row = rows_ + ring_.ReadSlot(r) * row_stride_;
      char* const first = file_buffer_.get() + buffered_bytes_;
      char* const end = detail::FormatLogRow(first, row, row_stride_, cell_memos_.get());
      buffered_bytes_ += static_cast<std::size_t>(end - first);
      ++buffered_rows_;
    }
    ring_.Release(batch);
    available -= batch;
    if (available == 0) available = ring_.Available();
  }
}

void CsvLogger::WriteBuffer() {
  if (buffered_bytes_ == 0 || write_failed_ || fd_ < 0) return;
  const auto [accepted, err] = WriteAll(fd_, file_buffer_.get(), buffered_bytes_);
  if (err != 0) {
    EndAfterFailedWrite(accepted, err);
    return;
  }
  written_.store(written_.load(std::memory_order_relaxed) + buffered_rows_,
                 std::memory_order_relaxed);
  file_bytes_ += accepted;
  buffered_bytes_ = 0;
  buffered_rows_ = 0;
}

void CsvLogger::EndAfterFailedWrite(std::size_t accepted_bytes, int err) {
  // The rows whose newline reached the file are whole; a torn one after them is cut off, so
  // the file ends with a whole row and every line parses.
  const char* const data = file_buffer_.get();
  std::uint64_t whole_rows = 0;
  std::size_t whole_bytes = 0;
  for (const char* p = data; p != data + accepted_bytes; ++p) {
    if (*p == '\n') {
      ++whole_rows;
      whole_bytes = static_cast<std::size_t>(p - data) + 1;
    }
  }
  std::string note;
  if (whole_bytes != accepted_bytes &&
      ::ftruncate(fd_, static_cast<off_t>(file_bytes_ + whole_bytes)) != 0) {
    note = "; its last row is torn (cutting it off failed: " + ErrnoText(errno) + ")";
  }
  written_.store(written_.load(std::memory_order_relaxed) + whole_rows,
                 std::memory_order_relaxed);
  lost_.store(lost_.load(std::memory_order_relaxed) + (buffered_rows_ - whole_rows),
              std::memory_order_relaxed);
  file_bytes_ += whole_bytes;
  buffered_bytes_ = 0;
  buffered_rows_ = 0;
  write_failed_ = true;
  RecordIoError("write", err, note);
}

void CsvLogger::RecordIoError(const char* what, int err, const std::string& note) {
  std::lock_guard lock(mutex_);
  if (!error_.empty()) return;
  error_reason_ = ErrnoText(err);
  error_ = std::string(what) + " '" + config_.path + "': " + error_reason_ + note;
}

std::uint64_t CsvLogger::rows_written() const noexcept {
  return written_.load(std::memory_order_relaxed);
}

std::uint64_t CsvLogger::rows_dropped() const noexcept {
  return producer_dropped_.load(std::memory_order_relaxed);
}

std::uint64_t CsvLogger::rows_lost() const noexcept {
  return lost_.load(std::memory_order_relaxed);
}

std::uint64_t CsvLogger::rows_selected() const noexcept {
  // The first offer is selected, then every `decimation`-th (TryLog's countdown starts at 0).
  const std::uint64_t offered = offered_.load(std::memory_order_relaxed);
  return (offered + config_.decimation - 1) / config_.decimation;
}

std::uint64_t CsvLogger::rows_offered() const noexcept {
  return offered_.load(std::memory_order_relaxed);
}

std::string CsvLogger::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

std::string CsvLogger::error_reason() const {
  std::lock_guard lock(mutex_);
  return error_reason_;
}

int CsvLogger::writer_sched_policy() const noexcept {
  return writer_policy_.load(std::memory_order_relaxed);
}

}  // namespace hiltwin::tracing
