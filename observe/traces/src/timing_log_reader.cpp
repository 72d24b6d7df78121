// ReadTimingLog: the timing log `hiltwin run --timing-log FILE` writes
// (tracing/timing_log_format.h). A dedicated line parser rather than ReadCsv: a 20 kHz minute is
// 1.2 M rows, read here in one linear pass (the shared line reader's large chunks,
// std::from_chars, no per-row allocation) straight into the TimingTrace, where ReadCsv would
// hold every cell as a double.
//
// Messages start "FILE:LINE" and, for a cell, "FILE:LINE:COL" with COL counting CSV fields
// from 1, as csv.h does.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "hiltwin/traces/trace_readers.h"
#include "hiltwin/tracing/csv.h"
#include "hiltwin/tracing/line_reader.h"
#include "hiltwin/tracing/timing_log_format.h"
#include "trace_reading.h"

namespace hiltwin::analysis {
namespace {

constexpr std::size_t kFieldCount = 1 + tracing::kTimingLogFields.size();
/// Column (1-based CSV field) of each value, for messages and the row parser.
enum Column : std::size_t {
  kTimeS = 1,
  kK,
  kRelease,
  kWake,
  kStart,
  kEnd,
  kIo,
  kSkipped,
  kMissed,
  kJudged
};
static_assert(kJudged == kFieldCount, "one Column per timing-log field");
/// Rows reserved up front at most, whatever planned_cycles says (a hand-edited file may lie).
constexpr std::uint64_t kMaxReservedRows = std::uint64_t{1} << 24;

std::string Quote(std::string_view text) {
  constexpr std::size_t kMaxQuoted = 60;
  if (text.size() > kMaxQuoted) return "'" + std::string(text.substr(0, kMaxQuoted)) + "...'";
  return "'" + std::string(text) + "'";
}

const char* ColumnName(std::size_t column) {
  return column == kTimeS ? "time_s" : tracing::kTimingLogFields[column - kK];
}

/// The file's lines through the shared bounded reader (tracing/line_reader.h): a line longer
/// than the CSV reader's cap is refused there, so a file without line breaks is not read whole.
class TimingLogLines {
 public:
  explicit TimingLogLines(const std::string& path) : path_(path), lines_(Open(path)) {}

  /// The next line, without its '\n' (nor a '\r' before it); false at the end of the file.
  /// `terminated` is false for a last line the file ends inside of.
  bool Next(std::string_view& line, bool& terminated) {
    const tracing::LineReader::Status status =
        Guard([&] { return lines_.Next(line, terminated); });
    if (status == tracing::LineReader::Status::kTooLong) {
      throw TraceReadError(path_ + ":" + std::to_string(lines_.line_number()) +
                           ": the line is longer than " + std::to_string(kMaxCsvLineBytes) +
                           " bytes, the most hiltwin reads as one CSV row; a timing log's rows "
                           "are under 200 bytes: this is not a timing log `hiltwin run "
                           "--timing-log FILE` wrote");
    }
    return status == tracing::LineReader::Status::kLine;
  }

  /// Whether nothing follows the last line returned.
  bool AtEnd() { return Guard([&] { return lines_.AtEnd(); }); }

  [[nodiscard]] std::size_t line_number() const noexcept { return lines_.line_number(); }

 private:
  static tracing::LineReader Open(const std::string& path) {
    try {
      return {path, kMaxCsvLineBytes};
    } catch (const std::system_error& error) {
      throw TraceReadError("cannot open the timing log " + path + ": " + error.code().message());
    }
  }
  template <typename Read>
  std::invoke_result_t<Read> Guard(Read read) {
    try {
      return read();
    } catch (const std::system_error& error) {
      throw TraceReadError(path_ + ":" + std::to_string(lines_.line_number() + 1) +
                           ": cannot read: " + error.code().message());
    }
  }

  const std::string& path_;
  tracing::LineReader lines_;
};

/// Reads one timing log into a TimingTrace; every method throws TraceReadError with the place.
class TimingLogParser {
 public:
  explicit TimingLogParser(const std::string& path) : path_(path), lines_(path) {}
  [[nodiscard]] TimingTrace Read();

 private:
  void ReadMagic();
  /// Reads the "# key=value" lines and returns the (whole) line after them: the header.
  std::string_view ReadPreamble();
  void ReadPreambleEntry(std::string_view entry);
  void ReadRule(std::string_view value);
  void CheckHeader(std::string_view line);
  void ReadRows();
  void ReadRow(std::string_view line, bool terminated);
  void Accept(const TracedCycle& cycle);

  template <typename T>
  T Integer(std::string_view text, const std::string& what) const;
  template <typename T>
  T Cell(std::string_view text, std::size_t column) const;

  [[nodiscard]] std::string Here() const {
    return path_ + ":" + std::to_string(lines_.line_number());
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw TraceReadError(Here() + ": " + what);
  }
  [[noreturn]] void FailAt(std::size_t column, const std::string& what) const {
    throw TraceReadError(CsvLocation(path_, lines_.line_number(), column) + ": " + what);
  }

  const std::string& path_;
  TimingLogLines lines_;
  TimingTrace trace_;
  bool has_period_ = false;
  bool has_deadline_ = false;
  bool has_planned_ = false;
  std::uint64_t next_release_ = 0;  ///< k the next row has when the logger dropped none
};

TimingTrace TimingLogParser::Read() {
  trace_.source = TraceSource::kTimingLog;
  trace_.path = path_;
  ReadMagic();
  CheckHeader(ReadPreamble());
  trace_.cycles.reserve(std::min(trace_.planned_cycles, kMaxReservedRows));
  ReadRows();
  trace_.complete = true;  // a torn last row is an error, so a trace read is whole
  return std::move(trace_);
}

void TimingLogParser::ReadMagic() {
  const std::string expected = "# " + std::string(tracing::kTimingLogMagic);
  std::string_view line;
  bool terminated = false;
  if (!lines_.Next(line, terminated)) {
    throw TraceReadError("not a hiltwin timing log: " + path_ +
                         " is empty; `hiltwin run --timing-log FILE` writes one");
  }
  if (line == expected) {
    if (!terminated) Fail("the file ends after its first line (it was cut while being written)");
    return;
  }
  const std::string_view family = "# hiltwin timing log ";
  if (line.starts_with(family)) {
    Fail("not a hiltwin timing log this hiltwin reads: its format is " + Quote(line.substr(2)) +
         ", this reader's is '" + std::string(tracing::kTimingLogMagic) +
         "'; read it with the hiltwin that wrote it");
  }
  Fail("not a hiltwin timing log: its first line is " + Quote(line) + ", not '" + expected +
       "'; `hiltwin run --timing-log FILE` writes one (for an LTTng trace, pass its folder)");
}

std::string_view TimingLogParser::ReadPreamble() {
  std::string_view line;
  bool terminated = false;
  while (lines_.Next(line, terminated)) {
    if (!terminated) Fail("the file ends inside its preamble (it was cut while being written)");
    if (!line.starts_with('#')) return line;
    if (!line.starts_with("# ")) Fail("preamble line " + Quote(line) + " is not '# key=value'");
    ReadPreambleEntry(line.substr(2));
  }
  Fail("the file ends before its header line 'time_s,k,...' (it was cut while being written)");
}

void TimingLogParser::ReadPreambleEntry(std::string_view entry) {
  const std::size_t equals = entry.find('=');
  if (equals == std::string_view::npos) {
    Fail("preamble line " + Quote(entry) + " is not '# key=value'");
  }
  const std::string_view key = entry.substr(0, equals);
  const std::string_view value = entry.substr(equals + 1);
  const auto once = [this, key](bool& seen) {
    if (seen) Fail("preamble key '" + std::string(key) + "' given twice");
    seen = true;
  };
  if (key == "period_ns") {
    once(has_period_);
    trace_.period_ns = Integer<std::int64_t>(value, "period_ns");
    if (trace_.period_ns <= 0) Fail("period_ns " + std::string(value) + " must be positive");
  } else if (key == "deadline_ns") {
    once(has_deadline_);
    trace_.deadline_ns = Integer<std::int64_t>(value, "deadline_ns");
    if (trace_.deadline_ns <= 0) Fail("deadline_ns " + std::string(value) + " must be positive");
  } else if (key == "planned_cycles") {
    once(has_planned_);
    trace_.planned_cycles = Integer<std::uint64_t>(value, "planned_cycles");
  } else if (key == "rule") {
    ReadRule(value);
  } else {
    Fail("unknown preamble key " + Quote(key) +
         " (a timing log has period_ns, deadline_ns, planned_cycles and rule)");
  }
}

void TimingLogParser::ReadRule(std::string_view value) {
  // "<kind> m=<m> k=<k> n=<n> max_miss_ppm=<ppm>", as runtime's MakeTimingLog writes it.
  std::array<std::string_view, 5> tokens{};
  std::size_t count = 0;
  for (std::size_t at = 0; at < value.size();) {
    const std::size_t space = std::min(value.find(' ', at), value.size());
    if (space > at) {
      if (count == tokens.size()) Fail("rule " + Quote(value) + " has more than 5 parts");
      tokens[count++] = value.substr(at, space - at);
    }
    at = space + 1;
  }
  std::uint64_t kind = detail::kRuleKindCount;
  for (std::uint64_t code = 0; count > 0 && code < detail::kRuleKindCount; ++code) {
    if (tokens[0] == qos::ToString(static_cast<qos::RuleKind>(code))) kind = code;
  }
  if (kind == detail::kRuleKindCount) {
    Fail("unknown rule kind " + Quote(count > 0 ? tokens[0] : value) +
         " (known: mk_firm, misses_in_window, max_consecutive_misses, miss_ratio)");
  }
  constexpr std::array<std::string_view, 4> kParameters = {"m=", "k=", "n=", "max_miss_ppm="};
  std::array<std::uint32_t, 4> numbers{};
  for (std::size_t i = 0; i < kParameters.size(); ++i) {
    const std::string_view token = tokens[i + 1];
    if (i + 1 >= count || !token.starts_with(kParameters[i])) {
      Fail("rule " + Quote(value) + ": expected '<kind> m=M k=K n=N max_miss_ppm=PPM'");
    }
    const std::string name(kParameters[i].substr(0, kParameters[i].size() - 1));
    numbers[i] = Integer<std::uint32_t>(token.substr(kParameters[i].size()), "rule " + name);
  }
  trace_.rules.push_back(
      detail::DecodeRule(kind, numbers[0], numbers[1], numbers[2], numbers[3], Here()));
}

void TimingLogParser::CheckHeader(std::string_view line) {
  std::string expected = "time_s";
  for (const char* name : tracing::kTimingLogFields) expected.append(",").append(name);
  if (line != expected) {
    Fail("the header is " + Quote(line) + "; a timing log's is '" + expected + "'");
  }
  const char* missing = !has_period_     ? "period_ns"
                        : !has_deadline_ ? "deadline_ns"
                        : !has_planned_  ? "planned_cycles"
                                         : nullptr;
  if (missing != nullptr) {
    Fail("the preamble above the header has no '# " + std::string(missing) + "=' line");
  }
}

template <typename T>
T TimingLogParser::Integer(std::string_view text, const std::string& what) const {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error == std::errc() && end == text.data() + text.size() && !text.empty()) return value;
  Fail(what + " " + Quote(text) + " is not an integer" +
       (error == std::errc::result_out_of_range ? " in range" : ""));
}

template <typename T>
T TimingLogParser::Cell(std::string_view text, std::size_t column) const {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error == std::errc() && end == text.data() + text.size() && !text.empty()) return value;
  FailAt(column, std::string(ColumnName(column)) + " " + Quote(text) + " is not " +
                     (error == std::errc::result_out_of_range ? "in range" : "an integer"));
}

void TimingLogParser::ReadRows() {
  std::string_view line;
  bool terminated = false;
  while (lines_.Next(line, terminated)) ReadRow(line, terminated);
  if (trace_.cycles.empty()) {
    throw TraceReadError(path_ + ": no cycle rows after the header (line " +
                         std::to_string(lines_.line_number()) +
                         "); the run ended before its first cycle");
  }
}

void TimingLogParser::ReadRow(std::string_view line, bool terminated) {
  std::array<std::string_view, kFieldCount + 1> cells{};
  std::size_t count = 0;
  for (std::size_t at = 0; count < cells.size();) {
    const std::size_t comma = std::min(line.find(',', at), line.size());
    cells[count++] = line.substr(at, comma - at);
    if (comma == line.size()) break;
    at = comma + 1;
  }
  if (!terminated || (count < kFieldCount && lines_.AtEnd())) {
    Fail("the last row is torn (the file was cut while being written); " +
         std::to_string(trace_.cycles.size()) + " complete rows before it");
  }
  if (count != kFieldCount) {
    Fail(std::string(count > kFieldCount ? "more than " : "") + std::to_string(count) +
         " fields; a timing-log row has " + std::to_string(kFieldCount) + " (time_s,k,...)");
  }
  double time_s = 0.0;
  const std::string_view time_text = cells[kTimeS - 1];
  const auto [end, error] =
      std::from_chars(time_text.data(), time_text.data() + time_text.size(), time_s);
  if (error != std::errc() || end != time_text.data() + time_text.size() ||
      !std::isfinite(time_s)) {
    FailAt(kTimeS, "time_s " + Quote(time_text) + " is not a finite number");
  }
  TracedCycle cycle;
  scheduler::TimingSample& sample = cycle.sample;
  sample.cycle = Cell<std::uint64_t>(cells[kK - 1], kK);
  sample.release_ns = Cell<std::int64_t>(cells[kRelease - 1], kRelease);
  sample.wake_ns = Cell<std::int64_t>(cells[kWake - 1], kWake);
  sample.start_ns = Cell<std::int64_t>(cells[kStart - 1], kStart);
  sample.end_ns = Cell<std::int64_t>(cells[kEnd - 1], kEnd);
  sample.io_ns = Cell<std::int64_t>(cells[kIo - 1], kIo);
  sample.releases_skipped = Cell<std::uint32_t>(cells[kSkipped - 1], kSkipped);
  const auto flag = [&](std::size_t column) {
    const auto value = Cell<std::uint8_t>(cells[column - 1], column);
    if (value > 1) FailAt(column, std::string(ColumnName(column)) + " must be 0 or 1");
    return value == 1;
  };
  sample.missed = flag(kMissed);
  cycle.judged = flag(kJudged);
  Accept(cycle);
}

void TimingLogParser::Accept(const TracedCycle& cycle) {
  const scheduler::TimingSample& sample = cycle.sample;
  if (!trace_.cycles.empty()) {
    const scheduler::TimingSample& last = trace_.cycles.back().sample;
    if (sample.cycle <= last.cycle) {
      FailAt(kK, "k " + std::to_string(sample.cycle) + " after k " + std::to_string(last.cycle) +
                     "; rows must come in increasing k");
    }
    if (sample.release_ns <= last.release_ns) {
      FailAt(kRelease, "release_ns " + std::to_string(sample.release_ns) +
                           " not after the row before's " + std::to_string(last.release_ns));
    }
  }
  const std::array<std::pair<std::size_t, scheduler::TimeNs>, 4> times = {
      {{kRelease, sample.release_ns},
       {kWake, sample.wake_ns},
       {kStart, sample.start_ns},
       {kEnd, sample.end_ns}}};
  for (std::size_t i = 1; i < times.size(); ++i) {
    if (times[i].second < times[i - 1].second) {
      FailAt(times[i].first, std::string(ColumnName(times[i].first)) + " " +
                                 std::to_string(times[i].second) + " before " +
                                 ColumnName(times[i - 1].first) + " " +
                                 std::to_string(times[i - 1].second) +
                                 " (a cycle's times are release <= wake <= start <= end)");
    }
  }
  if (sample.io_ns < 0) FailAt(kIo, "io_ns " + std::to_string(sample.io_ns) + " is negative");
  // Releases neither this row nor the one before account for: rows the logger dropped.
  if (sample.cycle > next_release_) trace_.discarded_events += sample.cycle - next_release_;
  next_release_ = sample.cycle + 1 + sample.releases_skipped;
  if (sample.missed) {
    TracedEvent miss;
    miss.kind = TracedEventKind::kDeadlineMiss;
    miss.k = sample.cycle;
    miss.a = sample.end_ns - sample.release_ns - trace_.deadline_ns;
    trace_.events.push_back(miss);
  }
  trace_.cycles.push_back(cycle);
}

}  // namespace

TimingTrace ReadTimingLog(const std::string& path) { return TimingLogParser(path).Read(); }

}  // namespace hiltwin::analysis
