// The kernel recording's two CSV files (format in kernel_events.h): written once at the end of
// a recording, read by `hiltwin trace --analyze`. The reader is a plain line parser, not the
// general CSV reader: names never hold commas (the writer replaces them), and every bad row
// must be named by file and line rather than skipped.
#include "hiltwin/traces/kernel_events.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "hiltwin/kernel_glue/os_calls.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;

constexpr const char* kEventsFile = "kernel_events.csv";
constexpr const char* kTasksFile = "kernel_tasks.csv";
constexpr std::string_view kCommentPrefix = "# hiltwin kernel events ";
// Version 2 added the preemption line; version 1 files (no such line) still read.
constexpr std::string_view kFormatVersion = "2";
constexpr std::array<std::string_view, 2> kReadableVersions = {"1", "2"};
constexpr std::string_view kPreemptionPrefix = "# preemption ";
constexpr std::string_view kPreemptionSeparator = " | ";
constexpr std::array<std::string_view, 14> kEventColumns = {
    "time_ns",   "cpu",       "event",      "pid",        "comm", "prio", "next_pid",
    "next_comm", "next_prio", "prev_state", "target_cpu", "irq",  "name", "address"};
constexpr std::array<std::string_view, 4> kTaskColumns = {"pid", "comm", "policy", "rt_priority"};
constexpr std::array<KernelEventKind, 9> kAllKinds = {
    KernelEventKind::kSchedSwitch,     KernelEventKind::kSchedWakeup,
    KernelEventKind::kIrqEntry,        KernelEventKind::kIrqExit,
    KernelEventKind::kLocalTimerEntry, KernelEventKind::kLocalTimerExit,
    KernelEventKind::kSoftirqEntry,    KernelEventKind::kSoftirqExit,
    KernelEventKind::kPageFaultUser};

/// Which cells an event of one kind fills (kernel_events.h); the others stay empty, so a
/// reader never mistakes a default (pid 0 is the idle task) for a recorded value.
struct Cells {
  bool task = false;  // pid, comm
  bool prio = false;
  bool next = false;  // next_pid, next_comm, next_prio, prev_state
  bool target_cpu = false;
  bool irq = false;
  bool name = false;
  bool address = false;
};

Cells CellsOf(KernelEventKind kind) {
  switch (kind) {
    case KernelEventKind::kSchedSwitch:
      return {.task = true, .prio = true, .next = true};
    case KernelEventKind::kSchedWakeup:
      return {.task = true, .prio = true, .target_cpu = true};
    case KernelEventKind::kIrqEntry:
      return {.irq = true, .name = true};
    case KernelEventKind::kIrqExit:
      return {.irq = true};
    case KernelEventKind::kSoftirqEntry:
    case KernelEventKind::kSoftirqExit:
      return {.irq = true, .name = true};
    case KernelEventKind::kPageFaultUser:
      return {.task = true, .address = true};
    case KernelEventKind::kLocalTimerEntry:
    case KernelEventKind::kLocalTimerExit:
      return {};
  }
  return {};
}

template <std::size_t N>
std::string JoinColumns(const std::array<std::string_view, N>& columns) {
  std::string line;
  for (std::string_view column : columns) {
    if (!line.empty()) line += ',';
    line += column;
  }
  return line;
}

// The two files' header rows, built from the column lists so they cannot disagree.
const std::string& EventsHeader() {
  static const std::string header = JoinColumns(kEventColumns);
  return header;
}
const std::string& TasksHeader() {
  static const std::string header = JoinColumns(kTaskColumns);
  return header;
}

// Names come from the kernel (comm is whatever a program called itself): a comma or line
// break in one would shift every later cell of the row.
void AppendText(std::string& line, std::string_view text) {
  for (char c : text) line += (c == ',' || c == '\n' || c == '\r') ? '_' : c;
}

template <typename Number>
void AppendNumber(std::string& line, Number value, int base = 10) {
  std::array<char, 24> digits{};
  const auto result = std::to_chars(digits.data(), digits.data() + digits.size(), value, base);
  line.append(digits.data(), result.ptr);
}

// One event as a row, ending in '\n'; cells that do not apply to its kind stay empty.
void AppendEventRow(std::string& line, const KernelEvent& event) {
  const Cells cells = CellsOf(event.kind);
  AppendNumber(line, event.time_ns);
  line += ',';
  AppendNumber(line, event.cpu);
  line += ',';
  line += ToString(event.kind);
  line += ',';
  if (cells.task) AppendNumber(line, event.pid);
  line += ',';
  if (cells.task) AppendText(line, event.comm);
  line += ',';
  if (cells.prio) AppendNumber(line, event.prio);
  line += ',';
  if (cells.next) AppendNumber(line, event.next_pid);
  line += ',';
  if (cells.next) AppendText(line, event.next_comm);
  line += ',';
  if (cells.next) AppendNumber(line, event.next_prio);
  line += ',';
  if (cells.next) AppendNumber(line, event.prev_state);
  line += ',';
  if (cells.target_cpu) AppendNumber(line, event.target_cpu);
  line += ',';
  if (cells.irq) AppendNumber(line, event.irq);
  line += ',';
  if (cells.name) AppendText(line, event.name);
  line += ',';
  if (cells.address) {
    line += "0x";
    AppendNumber(line, event.address, 16);
  }
  line += '\n';
}

std::string CommentLine(const KernelTrace& trace) {
  std::string line(kCommentPrefix);
  line += kFormatVersion;
  line += " cpus=";
  for (std::size_t i = 0; i < trace.cpus.size(); ++i) {
    if (i > 0) line += ',';
    AppendNumber(line, trace.cpus[i]);
  }
  line += " lost=";
  AppendNumber(line, trace.lost_events);
  line += '\n';
  return line;
}

// "# preemption PREEMPT_NONE | kernel config", or nothing when the model was not recorded.
std::string PreemptionLine(const KernelTrace& trace) {
  if (trace.preemption_model.empty()) return {};
  std::string line(kPreemptionPrefix);
  const auto append = [&line](std::string_view text) {
    for (char c : text) line += (c == '|' || c == '\n' || c == '\r') ? '_' : c;
  };
  append(trace.preemption_model);
  line += kPreemptionSeparator;
  append(trace.preemption_source);
  line += '\n';
  return line;
}

// An output file that reports a failed open or write by name.
class OutputFile {
 public:
  explicit OutputFile(fs::path path) : path_(std::move(path)), out_(path_, std::ios::binary) {
    if (!out_) Fail("cannot create the file");
  }
  void Write(std::string_view text) {
    out_.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
  void Close() {
    out_.close();
    if (!out_) Fail("cannot write the file (disk full?)");
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(path_.string() + ": " + what + " (" + kernel_glue::ErrnoText(errno) +
                             ")");
  }
  fs::path path_;
  std::ofstream out_;
};

// The events in time order. The recorder drains each CPU's buffer in turn, so consecutive
// drains interleave CPUs; a stable sort keeps each CPU's own order for equal times.
std::vector<std::size_t> IndicesByTime(const std::vector<KernelEvent>& events) {
  std::vector<std::size_t> order(events.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto earlier = [&events](std::size_t a, std::size_t b) {
    return events[a].time_ns < events[b].time_ns;
  };
  if (!std::is_sorted(order.begin(), order.end(), earlier)) {
    std::stable_sort(order.begin(), order.end(), earlier);
  }
  return order;
}

void WriteEvents(const fs::path& path, const KernelTrace& trace) {
  OutputFile out(path);
  out.Write(CommentLine(trace));
  out.Write(PreemptionLine(trace));
  out.Write(EventsHeader() + "\n");
  std::string line;
  for (std::size_t index : IndicesByTime(trace.events)) {
    line.clear();
    AppendEventRow(line, trace.events[index]);
    out.Write(line);
  }
  out.Close();
}

void WriteTasks(const fs::path& path, const std::vector<KernelTask>& tasks) {
  OutputFile out(path);
  out.Write(TasksHeader() + "\n");
  std::string line;
  for (const KernelTask& task : tasks) {
    line.clear();
    AppendNumber(line, task.pid);
    line += ',';
    AppendText(line, task.comm);
    line += ',';
    AppendText(line, task.policy);
    line += ',';
    AppendNumber(line, task.rt_priority);
    line += '\n';
    out.Write(line);
  }
  out.Close();
}

// Reads a file line by line, knowing where it is for messages.
class EventsFileLines {
 public:
  explicit EventsFileLines(fs::path path) : path_(std::move(path)), in_(path_, std::ios::binary) {
    if (!in_) {
      throw TraceReadError(path_.string() + ": cannot open (" + kernel_glue::ErrnoText(errno) +
                           "): record with `hiltwin trace --kernel`, or analyse without it");
    }
  }
  /// The next line without its '\n'; false at the end. A last line without '\n' is torn
  /// (the writer ends every line): the recording was cut short.
  bool Next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_number_;
    if (in_.eof()) Fail("torn last line (no newline at the end of the file: cut short?)");
    return true;
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw TraceReadError(path_.string() + ":" + std::to_string(line_number_) + ": " + what);
  }
  /// Like Next, but the line must be there.
  void Expect(std::string& line, std::string_view what) {
    if (!Next(line)) {
      ++line_number_;
      Fail("missing " + std::string(what) + " (the file ends here)");
    }
  }

 private:
  fs::path path_;
  std::ifstream in_;
  std::size_t line_number_ = 0;
};

std::vector<std::string_view> SplitCells(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma - start));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

// A number cell: empty gives `fallback`; anything but a whole number is an error.
template <typename Number>
Number ParseNumber(const EventsFileLines& reader, std::string_view cell, std::string_view column,
                   Number fallback, int base = 10) {
  if (cell.empty()) return fallback;
  std::string_view digits = cell;
  if (base == 16) {
    if (!digits.starts_with("0x")) {
      reader.Fail("bad number '" + std::string(cell) + "' in column " + std::string(column) +
                  " (expected hex with 0x)");
    }
    digits.remove_prefix(2);
  }
  Number value{};
  const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
  if (result.ec != std::errc() || result.ptr != digits.data() + digits.size() || digits.empty()) {
    reader.Fail("bad number '" + std::string(cell) + "' in column " + std::string(column));
  }
  return value;
}

KernelEventKind ParseKind(const EventsFileLines& reader, std::string_view cell) {
  for (KernelEventKind kind : kAllKinds) {
    if (cell == ToString(kind)) return kind;
  }
  std::string known;
  for (KernelEventKind kind : kAllKinds) {
    if (!known.empty()) known += ", ";
    known += ToString(kind);
  }
  reader.Fail("unknown event name '" + std::string(cell) + "' (known: " + known + ")");
}

KernelEvent ParseEventRow(const EventsFileLines& reader, std::string_view line) {
  const std::vector<std::string_view> cells = SplitCells(line);
  if (cells.size() != kEventColumns.size()) {
    reader.Fail(std::to_string(cells.size()) + " fields, expected " +
                std::to_string(kEventColumns.size()) + " (" + EventsHeader() + ")");
  }
  KernelEvent event;
  event.time_ns = ParseNumber<std::int64_t>(reader, cells[0], kEventColumns[0], 0);
  event.cpu = ParseNumber<int>(reader, cells[1], kEventColumns[1], 0);
  event.kind = ParseKind(reader, cells[2]);
  event.pid = ParseNumber<int>(reader, cells[3], kEventColumns[3], 0);
  event.comm = cells[4];
  event.prio = ParseNumber<int>(reader, cells[5], kEventColumns[5], 0);
  event.next_pid = ParseNumber<int>(reader, cells[6], kEventColumns[6], 0);
  event.next_comm = cells[7];
  event.next_prio = ParseNumber<int>(reader, cells[8], kEventColumns[8], 0);
  event.prev_state = ParseNumber<std::int64_t>(reader, cells[9], kEventColumns[9], 0);
  event.target_cpu = ParseNumber<int>(reader, cells[10], kEventColumns[10], -1);
  event.irq = ParseNumber<int>(reader, cells[11], kEventColumns[11], -1);
  event.name = cells[12];
  event.address = ParseNumber<std::uint64_t>(reader, cells[13], kEventColumns[13], 0, 16);
  return event;
}

// "# hiltwin kernel events 2 cpus=0,1 lost=0" into trace.cpus and trace.lost_events.
void ParseCommentLine(const EventsFileLines& reader, std::string_view line, KernelTrace& trace) {
  const std::string prefix(kCommentPrefix);
  const auto version = std::find_if(
      kReadableVersions.begin(), kReadableVersions.end(), [&](std::string_view v) {
        return line.starts_with(prefix + std::string(v) + " ");
      });
  if (version == kReadableVersions.end()) {
    reader.Fail("missing the comment line '" + prefix + std::string(kFormatVersion) +
                " cpus=<list> lost=<count>' (versions 1 and 2 are read; found '" +
                std::string(line.substr(0, 60)) + "')");
  }
  line.remove_prefix(prefix.size() + version->size() + 1);
  const std::size_t lost_at = line.find(" lost=");
  if (!line.starts_with("cpus=") || lost_at == std::string_view::npos) {
    reader.Fail("the comment line needs 'cpus=<list> lost=<count>'");
  }
  const std::string_view cpu_list = line.substr(5, lost_at - 5);
  if (!cpu_list.empty()) {
    for (std::string_view cpu : SplitCells(cpu_list)) {
      trace.cpus.push_back(ParseNumber<int>(reader, cpu, "cpus", 0));
    }
  }
  trace.lost_events = ParseNumber<std::uint64_t>(reader, line.substr(lost_at + 6), "lost", 0);
}

void ExpectHeader(EventsFileLines& reader, std::string& line, const std::string& header) {
  reader.Expect(line, "the header row");
  if (line != header) reader.Fail("missing the header row '" + header + "'");
}

// "# preemption <model> | <source>" into the trace; false when `line` is not that line.
bool ParsePreemptionLine(const EventsFileLines& reader, std::string_view line,
                         KernelTrace& trace) {
  if (!line.starts_with(kPreemptionPrefix)) return false;
  line.remove_prefix(kPreemptionPrefix.size());
  const std::size_t separator = line.find(kPreemptionSeparator);
  if (separator == std::string_view::npos || separator == 0) {
    reader.Fail("the preemption line needs '" + std::string(kPreemptionPrefix) + "<model>" +
                std::string(kPreemptionSeparator) + "<how it was told>'");
  }
  trace.preemption_model = line.substr(0, separator);
  trace.preemption_source = line.substr(separator + kPreemptionSeparator.size());
  return true;
}

void ReadEvents(const fs::path& path, KernelTrace& trace) {
  EventsFileLines reader(path);
  std::string line;
  reader.Expect(line, "the comment line");
  ParseCommentLine(reader, line, trace);
  reader.Expect(line, "the header row");
  if (ParsePreemptionLine(reader, line, trace)) reader.Expect(line, "the header row");
  if (line != EventsHeader()) reader.Fail("missing the header row '" + EventsHeader() + "'");
  while (reader.Next(line)) trace.events.push_back(ParseEventRow(reader, line));
  const auto earlier = [](const KernelEvent& a, const KernelEvent& b) {
    return a.time_ns < b.time_ns;
  };
  if (!std::is_sorted(trace.events.begin(), trace.events.end(), earlier)) {
    std::stable_sort(trace.events.begin(), trace.events.end(), earlier);
  }
}

void ReadTasks(const fs::path& path, KernelTrace& trace) {
  EventsFileLines reader(path);
  std::string line;
  ExpectHeader(reader, line, TasksHeader());
  while (reader.Next(line)) {
    const std::vector<std::string_view> cells = SplitCells(line);
    if (cells.size() != kTaskColumns.size()) {
      reader.Fail(std::to_string(cells.size()) + " fields, expected " +
                  std::to_string(kTaskColumns.size()) + " (" + TasksHeader() + ")");
    }
    KernelTask task;
    task.pid = ParseNumber<int>(reader, cells[0], kTaskColumns[0], 0);
    task.comm = cells[1];
    task.policy = cells[2];
    task.rt_priority = ParseNumber<int>(reader, cells[3], kTaskColumns[3], 0);
    trace.tasks.push_back(std::move(task));
  }
}

}  // namespace

const char* ToString(KernelEventKind kind) noexcept {
  switch (kind) {
    case KernelEventKind::kSchedSwitch:
      return "sched_switch";
    case KernelEventKind::kSchedWakeup:
      return "sched_wakeup";
    case KernelEventKind::kIrqEntry:
      return "irq_handler_entry";
    case KernelEventKind::kIrqExit:
      return "irq_handler_exit";
    case KernelEventKind::kLocalTimerEntry:
      return "local_timer_entry";
    case KernelEventKind::kLocalTimerExit:
      return "local_timer_exit";
    case KernelEventKind::kSoftirqEntry:
      return "softirq_entry";
    case KernelEventKind::kSoftirqExit:
      return "softirq_exit";
    case KernelEventKind::kPageFaultUser:
      return "page_fault_user";
  }
  return "unknown";
}

void WriteKernelTrace(const std::string& dir, const KernelTrace& trace) {
  WriteEvents(fs::path(dir) / kEventsFile, trace);
  WriteTasks(fs::path(dir) / kTasksFile, trace.tasks);
}

KernelTrace ReadKernelTrace(const std::string& dir) {
  KernelTrace trace;
  ReadEvents(fs::path(dir) / kEventsFile, trace);
  ReadTasks(fs::path(dir) / kTasksFile, trace);
  return trace;
}

bool HasKernelTrace(const std::string& dir) {
  std::error_code error;
  return fs::is_regular_file(fs::path(dir) / kEventsFile, error);
}

}  // namespace hiltwin::analysis
