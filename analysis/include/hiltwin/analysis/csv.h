#pragma once
/// Reading the CSV files that 20-sim's "Save Data To File" and hiltwin's own logs write: a
/// header row, then one row per sample, first column time in seconds (thesis appendix B §5).

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hiltwin::analysis {

/// A bad input file, column or flag. what() says what was wrong, where (file:line:column or
/// the flag) and what to do; the command line maps it to exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One CSV file held column by column. Column 0 is time in seconds.
struct CsvTable {
  std::string path;                          ///< where it came from (for messages)
  std::vector<std::string> names;            ///< header names; "1", "2", ... without header
  bool has_header = true;                    ///< false when the first row was numbers
  std::size_t header_line = 0;               ///< 1-based file line of the header (0: none)
  std::vector<std::vector<double>> columns;  ///< columns[c][row]
  std::vector<std::size_t> lines;            ///< 1-based file line of each data row

  /// Number of data rows.
  [[nodiscard]] std::size_t rows() const noexcept { return lines.size(); }
  /// "FILE:LINE:COL" for data row `row` and 0-based column `column`.
  [[nodiscard]] std::string Where(std::size_t row, std::size_t column) const;
  /// "column N 'name'" for a 0-based column.
  [[nodiscard]] std::string ColumnLabel(std::size_t column) const;
};

/// Reads and checks `path`: every cell a finite number, every row as wide as the header, time
/// strictly increasing, at least two rows. Separator ',', ';' or tab (taken from the header
/// line), quoted header names, '#' comment lines and blank lines are accepted. Throws
/// InputError naming file, line and column.
[[nodiscard]] CsvTable ReadCsv(const std::string& path);

/// As ReadCsv, on text already in memory; `path` only names the source in messages.
[[nodiscard]] CsvTable ParseCsv(std::string_view text, const std::string& path);

/// Finds a column by exact header name, else by 1-based index ("3"). Time (column 1) is
/// refused. Returns the 0-based column. `flag` names the option in messages. Throws InputError.
[[nodiscard]] std::size_t ResolveColumn(const CsvTable& table, const std::string& selector,
                                        std::string_view flag);

}  // namespace hiltwin::analysis
