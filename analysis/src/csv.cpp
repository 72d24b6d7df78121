#include "hiltwin/analysis/csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

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
// (20-sim quotes its header names, e.g. "model\position").
std::vector<Field> SplitLine(std::string_view line, char separator) {
  std::vector<Field> fields;
  std::size_t i = 0;
  while (true) {
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

}  // namespace

std::string CsvTable::Where(std::size_t row, std::size_t column) const {
  return path + ":" + std::to_string(lines.at(row)) + ":" + std::to_string(column + 1);
}

std::string CsvTable::ColumnLabel(std::size_t column) const {
  std::string label = "column " + std::to_string(column + 1);
  if (has_header) label += " " + Quote(names.at(column));
  return label;
}

CsvTable ParseCsv(std::string_view text, const std::string& path) {
  // Excel and Windows editors save "CSV UTF-8" with a byte order mark, which would otherwise
  // become part of the first header name (or make the first time cell "not a number").
  constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
  if (text.starts_with(kUtf8Bom)) text.remove_prefix(kUtf8Bom.size());
  CsvTable table;
  table.path = path;
  char separator = ',';
  bool have_layout = false;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view raw = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const std::string_view line = Trim(raw);
    if (line.empty() || line.front() == '#') {
      if (end == text.size()) break;
      continue;
    }
    if (!have_layout) {
      separator = DetectSeparator(line);
      const std::vector<Field> fields = SplitLine(line, separator);
      bool all_numbers = true;
      for (const Field& field : fields) {
        double unused = 0.0;
        if (field.quoted || ParseNumber(field.text, unused) == NumberStatus::kNotNumber) {
          all_numbers = false;
        }
      }
      have_layout = true;
      table.columns.resize(fields.size());
      if (!all_numbers) {
        table.has_header = true;
        table.header_line = line_no;
        for (std::size_t c = 0; c < fields.size(); ++c) {
          std::string name = fields[c].text;
          if (name.empty()) name = std::to_string(c + 1);
          table.names.push_back(std::move(name));
        }
        if (fields.size() < 2) {
          throw InputError(path + ":" + std::to_string(line_no) +
                           ": the header has one column; need time plus at least one curve "
                           "(separators accepted: ',' ';' tab)");
        }
        if (end == text.size()) break;
        continue;
      }
      table.has_header = false;
      for (std::size_t c = 0; c < fields.size(); ++c) table.names.push_back(std::to_string(c + 1));
    }
    const std::vector<Field> fields = SplitLine(line, separator);
    if (fields.size() != table.columns.size()) {
      throw InputError(path + ":" + std::to_string(line_no) + ": row has " +
                       std::to_string(fields.size()) + " cells but " +
                       (table.has_header ? "the header has " : "the first row has ") +
                       std::to_string(table.columns.size()) +
                       "; every row needs one value per column (check for a missing or extra "
                       "separator)");
    }
    for (std::size_t c = 0; c < fields.size(); ++c) {
      double value = 0.0;
      const NumberStatus status = ParseNumber(fields[c].text, value);
      const std::string where = path + ":" + std::to_string(line_no) + ":" + std::to_string(c + 1);
      const std::string label = table.has_header ? " (" + Quote(table.names[c]) + ")" : "";
      if (status == NumberStatus::kNotNumber) {
        throw InputError(where + label + ": " +
                         (fields[c].text.empty() ? std::string("empty cell")
                                                 : Quote(fields[c].text) + " is not a number") +
                         "; every data cell must be a number with '.' as decimal point");
      }
      if (status == NumberStatus::kNotFinite) {
        throw InputError(where + label + ": " + Quote(fields[c].text) +
                         " is not a finite number (NaN or Inf); remove or fix that row");
      }
      table.columns[c].push_back(value);
    }
    table.lines.push_back(line_no);
    const std::vector<double>& time = table.columns[0];
    const std::size_t n = time.size();
    if (n >= 2 && !(time[n - 1] > time[n - 2])) {
      throw InputError(path + ":" + std::to_string(line_no) + ":1: time " +
                       std::to_string(time[n - 1]) +
                       (time[n - 1] == time[n - 2] ? " repeats" : " goes backwards from") +
                       " line " + std::to_string(table.lines[n - 2]) + " (" +
                       std::to_string(time[n - 2]) +
                       "); the first column must be time in seconds, strictly increasing "
                       "(remove duplicate rows, or sort the file)");
    }
    if (end == text.size()) break;
  }
  if (!have_layout) {
    throw InputError(path + ": empty file; need a header row and at least two data rows");
  }
  if (table.rows() < 2) {
    const std::size_t last_line = table.lines.empty() ? table.header_line : table.lines.back();
    throw InputError(path + ":" + std::to_string(last_line) + ": " + std::to_string(table.rows()) +
                     " data row" + (table.rows() == 1 ? "" : "s") +
                     "; need at least two samples to assess a curve");
  }
  return table;
}

CsvTable ReadCsv(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError(path + ": cannot open for reading; check the path and permissions");
  }
  std::ostringstream buffer;
  buffer << file.rdbuf();
  return ParseCsv(buffer.str(), path);
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
