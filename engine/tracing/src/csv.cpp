#include "hiltwin/tracing/csv.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <system_error>
#include <utility>

#include "hiltwin/tracing/line_reader.h"

namespace hiltwin::analysis {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) {
    s.remove_prefix(1);
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

struct Field {
  std::string text;
  bool quoted = false;
};

// Splits one line; a field in double quotes may hold the separator and "" for a quote
// (20-sim quotes its header names, e.g. "model\position"). Stops after kMaxCsvCells + 1 fields:
// one more than the cap is enough to refuse the row.
std::vector<Field> SplitLine(std::string_view line, char separator) {
  std::vector<Field> fields;
  std::size_t i = 0;
  while (fields.size() <= kMaxCsvCells) {
    Field field;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t') && line[i] != separator) ++i;
    if (i < line.size() && line[i] == '"') {
      field.quoted = true;
      ++i;
      while (i < line.size()) {
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            field.text.push_back('"');
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        field.text.push_back(line[i++]);
      }
      while (i < line.size() && line[i] != separator) ++i;  // ignore anything after the quote
    } else {
      const std::size_t start = i;
      while (i < line.size() && line[i] != separator) ++i;
      field.text = std::string(Trim(line.substr(start, i - start)));
    }
    fields.push_back(std::move(field));
    if (i >= line.size()) break;
    ++i;  // skip the separator
  }
  return fields;
}

enum class NumberStatus { kOk, kNotNumber, kNotFinite };

NumberStatus ParseNumber(std::string_view text, double& value) {
  text = Trim(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return NumberStatus::kNotNumber;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  const auto result = std::from_chars(first, last, value);
  if (result.ec == std::errc::result_out_of_range) return NumberStatus::kNotFinite;
  if (result.ec != std::errc() || result.ptr != last) return NumberStatus::kNotNumber;
  if (!std::isfinite(value)) return NumberStatus::kNotFinite;
  return NumberStatus::kOk;
}

char DetectSeparator(std::string_view line) {
  if (line.find(',') != std::string_view::npos) return ',';
  if (line.find(';') != std::string_view::npos) return ';';
  if (line.find('\t') != std::string_view::npos) return '\t';
  return ',';
}

std::string Quote(std::string_view s) {
  std::string out = "'";
  out += s;
  out += "'";
  return out;
}

// "FILE:LINE:COL: column 'name': " (the name only with a header), the start of a cell message.
std::string CellPrefix(const CsvTable& table, std::size_t line_no, std::size_t column) {
  std::string prefix = CsvLocation(table.path, line_no, column + 1) + ": ";
  if (table.has_header) prefix += "column " + Quote(table.names.at(column)) + ": ";
  return prefix;
}

// Takes the header, or the names "1", "2", ... when the first row holds only numbers. Returns
// whether the row was a header (and so holds no data).
bool ReadLayout(CsvTable& table, const std::vector<Field>& fields, std::size_t line_no,
                const CsvRules& rules) {
  table.has_header = !std::all_of(fields.begin(), fields.end(), [](const Field& field) {
    double unused = 0.0;
    return !field.quoted && ParseNumber(field.text, unused) != NumberStatus::kNotNumber;
  });
  table.header_line = table.has_header ? line_no : 0;
  table.columns.resize(fields.size());
  for (std::size_t c = 0; c < fields.size(); ++c) {
    const bool named = table.has_header && !fields[c].text.empty();
    table.names.push_back(named ? fields[c].text : std::to_string(c + 1));
  }
  if (rules.check_layout) rules.check_layout(table, line_no);
  if (fields.size() < 2) {
    throw InputError(CsvLocation(table.path, line_no, 2) + ": " +
                     (table.has_header ? "the header" : "the first row") +
                     " has one column; need time plus at least one more (separators accepted: "
                     "',' ';' tab)");
  }
  return table.has_header;
}

double ReadCell(const CsvTable& table, const Field& field, std::size_t line_no,
                std::size_t column) {
  double value = 0.0;
  const NumberStatus status = ParseNumber(field.text, value);
  if (status == NumberStatus::kOk) return value;
  const std::string prefix = CellPrefix(table, line_no, column);
  if (status == NumberStatus::kNotFinite) {
    throw InputError(prefix + Quote(field.text) +
                     " is not finite (NaN or Inf); replace it with a finite number or remove "
                     "the row");
  }
  throw InputError(prefix +
                   (field.text.empty() ? std::string("empty cell")
                                       : Quote(field.text) + " is not a number") +
                   "; every data cell must be a number with '.' as decimal point");
}

// Checks the time of the row just added against the rows before it.
void CheckTime(const CsvTable& table, TimeOrder order) {
  const std::vector<double>& time = table.columns[0];
  const std::size_t n = time.size();
  if (n < 2 || time[n - 1] > time[n - 2]) return;
  const bool strict = order == TimeOrder::kStrictlyIncreasing;
  const std::string rule = strict ? "the first column must be time in seconds, strictly increasing"
                                  : "the first column must be time in seconds, never decreasing";
  const std::string what = table.Where(n - 1, 0) + ": time " + NumberText(time[n - 1]) + " s";
  const std::string previous_line = "line " + std::to_string(table.lines[n - 2]);
  if (time[n - 1] < time[n - 2]) {
    throw InputError(what + " is earlier than the previous row's " + NumberText(time[n - 2]) +
                     " s (" + previous_line + "); " + rule + ": sort the rows by time");
  }
  if (strict) {
    throw InputError(what + " repeats the previous row's (" + previous_line + "); " + rule +
                     ": remove the duplicate row");
  }
  if (n >= 3 && time[n - 3] == time[n - 1]) {
    throw InputError(what + " is on a third row (lines " + std::to_string(table.lines[n - 3]) +
                     ", " + std::to_string(table.lines[n - 2]) + " and " +
                     std::to_string(table.lines[n - 1]) +
                     "); a sudden step is two rows with the same time (before and after): "
                     "remove the extra row");
  }
}

void ReadRow(CsvTable& table, const std::vector<Field>& fields, std::size_t line_no,
             TimeOrder order) {
  const std::size_t width = table.columns.size();
  if (fields.size() != width) {
    // Point at the first cell that is missing or one too many.
    throw InputError(CsvLocation(table.path, line_no, std::min(fields.size(), width) + 1) +
                     ": row has " + std::to_string(fields.size()) + " cells but " +
                     (table.has_header ? "the header has " : "the first row has ") +
                     std::to_string(width) +
                     "; every row needs one value per column (check for a missing or extra "
                     "separator)");
  }
  for (std::size_t c = 0; c < width; ++c) {
    table.columns[c].push_back(ReadCell(table, fields[c], line_no, c));
  }
  table.lines.push_back(line_no);
  CheckTime(table, order);
}

void CheckRowCount(const CsvTable& table, std::string_view purpose) {
  if (table.columns.empty()) {
    throw InputError(CsvLocation(table.path, 1, 1) +
                     ": empty file; need a header row and at least two data rows " +
                     std::string(purpose));
  }
  if (table.rows() < 2) {
    const std::size_t last_line = table.lines.empty() ? table.header_line : table.lines.back();
    throw InputError(table.path + ":" + std::to_string(last_line) + ": " +
                     std::to_string(table.rows()) + " data row" + (table.rows() == 1 ? "" : "s") +
                     "; need at least two rows " + std::string(purpose));
  }
}

// Where a line is refused for its length: its text is not kept, so only the line is named.
[[noreturn]] void ThrowLineTooLong(const std::string& path, std::size_t line_no) {
  throw InputError(path + ":" + std::to_string(line_no) + ": the line is longer than " +
                   std::to_string(kMaxCsvLineBytes) +
                   " bytes, the most hiltwin reads as one CSV row; a row holds a time and its "
                   "values: check that the file is a CSV file with one row per line");
}

tracing::LineReader OpenLines(const std::string& path) {
  try {
    return {path, kMaxCsvLineBytes};
  } catch (const std::system_error& error) {
    throw InputError(path + ": cannot open for reading (" + error.code().message() +
                     "); check the path and permissions");
  }
}

// Takes a file's lines one at a time, so a file need not be held whole.
class CsvBuilder {
 public:
  CsvBuilder(const std::string& path, const CsvRules& rules) : rules_(rules) {
    table_.path = path;
  }

  // One line without its line break; `line_no` is 1-based.
  void Add(std::string_view line, std::size_t line_no) {
    // Excel and Windows editors save "CSV UTF-8" with a byte order mark, which would otherwise
    // become part of the first header name (or make the first time cell "not a number").
    constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
    if (line_no == 1 && line.starts_with(kUtf8Bom)) line.remove_prefix(kUtf8Bom.size());
    line = Trim(line);
    if (line.empty() || line.front() == '#') return;
    if (table_.columns.empty()) separator_ = DetectSeparator(line);
    const std::vector<Field> fields = SplitLine(line, separator_);
    if (fields.size() > kMaxCsvCells) {
      throw InputError(CsvLocation(table_.path, line_no, kMaxCsvCells + 1) +
                       ": the row has more than " + std::to_string(kMaxCsvCells) +
                       " cells, the most hiltwin reads in one CSV row; keep the time column "
                       "and the columns you need");
    }
    if (table_.columns.empty() && ReadLayout(table_, fields, line_no, rules_)) return;
    ReadRow(table_, fields, line_no, rules_.time_order);
  }

  CsvTable Finish() {
    CheckRowCount(table_, rules_.purpose);
    return std::move(table_);
  }

 private:
  const CsvRules& rules_;
  CsvTable table_;
  char separator_ = ',';
};

}  // namespace

std::string CsvLocation(std::string_view path, std::size_t line, std::size_t column) {
  return std::string(path) + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string NumberText(double value) {
  std::array<char, 32> text{};
  const auto result = std::to_chars(text.data(), text.data() + text.size(), value);
  return std::string(text.data(), result.ptr);
}

std::string CsvTable::Where(std::size_t row, std::size_t column) const {
  return CsvLocation(path, lines.at(row), column + 1);
}

std::string CsvTable::ColumnLabel(std::size_t column) const {
  std::string label = "column " + std::to_string(column + 1);
  if (has_header) label += " " + Quote(names.at(column));
  return label;
}

CsvTable ParseCsv(std::string_view text, const std::string& path, const CsvRules& rules) {
  CsvBuilder builder(path, rules);
  std::size_t line_no = 0;
  for (std::size_t pos = 0; pos <= text.size();) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (line.ends_with('\r')) line.remove_suffix(1);
    if (line.size() > kMaxCsvLineBytes) ThrowLineTooLong(path, line_no);
    builder.Add(line, line_no);
  }
  return builder.Finish();
}

CsvTable ReadCsv(const std::string& path, const CsvRules& rules) {
  tracing::LineReader lines = OpenLines(path);
  CsvBuilder builder(path, rules);
  std::string_view line;
  try {
    for (;;) {
      const tracing::LineReader::Status status = lines.Next(line);
      if (status == tracing::LineReader::Status::kEnd) break;
      if (status == tracing::LineReader::Status::kTooLong) {
        ThrowLineTooLong(path, lines.line_number());
      }
      builder.Add(line, lines.line_number());
    }
  } catch (const std::system_error& error) {
    throw InputError(path + ":" + std::to_string(lines.line_number() + 1) + ": cannot read (" +
                     error.code().message() + "); check that it is a readable file");
  }
  return builder.Finish();
}

std::size_t ResolveColumn(const CsvTable& table, const std::string& selector,
                          std::string_view flag) {
  const std::string where = table.path + ":" + std::to_string(std::max<std::size_t>(table.header_line, 1));
  std::string available;
  for (std::size_t c = 0; c < table.names.size(); ++c) {
    if (c > 0) available += ", ";
    available += std::to_string(c + 1) + "=" + Quote(table.names[c]);
  }
  const auto it = std::find(table.names.begin(), table.names.end(), selector);
  std::size_t column = table.names.size();
  if (table.has_header && it != table.names.end()) {
    column = static_cast<std::size_t>(it - table.names.begin());
  } else if (!selector.empty() &&
             std::all_of(selector.begin(), selector.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
    std::size_t index = 0;
    const auto result = std::from_chars(selector.data(), selector.data() + selector.size(), index);
    if (result.ec == std::errc() && index >= 1 && index <= table.names.size()) column = index - 1;
  }
  if (column == table.names.size()) {
    throw InputError(where + ": " + std::string(flag) + " " + Quote(selector) +
                     ": no such column (columns: " + available +
                     "); give a header name or a 1-based column index");
  }
  if (column == 0) {
    throw InputError(where + ": " + std::string(flag) + " " + Quote(selector) +
                     " is column 1, which is time; pick a curve column (columns: " + available + ")");
  }
  return column;
}

}  // namespace hiltwin::analysis
