#pragma once
/// Reading the CSV files that 20-sim's "Save Data To File" and hiltwin's own logs write: a
/// header row, then one row per sample, first column time in seconds (thesis appendix B §5).
/// The one reader for every CSV hiltwin takes in: curves for `hiltwin assess` and input
/// profiles for `hiltwin run --input`. Columns in messages count CSV fields from 1, as a
/// spreadsheet numbers them.

#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hiltwin::analysis {

/// The longest line, in bytes without its line break, and the most cells of one row that the
/// reader takes: far beyond any profile, 20-sim export or hiltwin log (a log row of the RELbot
/// is under 300 bytes and 15 cells), and small enough that a file without line breaks is refused
/// after 64 KiB instead of being read whole. docs/credibility.md ("Input") documents both.
constexpr std::size_t kMaxCsvLineBytes = 65536;
constexpr std::size_t kMaxCsvCells = 1024;

/// A bad input file, column or option. what() says what was wrong, where (file:line:column or
/// the option) and what to do; the command line maps it to exit code 2.
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

/// How the time column must progress from row to row.
enum class TimeOrder {
  kStrictlyIncreasing,  ///< samples of a curve: each time later than the one before
  kStepsAllowed,        ///< knots of a signal: never earlier; two rows share a time at a step
};

/// What a file must hold besides well-formed numbers. The defaults describe a curve file.
struct CsvRules {
  TimeOrder time_order = TimeOrder::kStrictlyIncreasing;
  /// Why the rows are needed, ending the message of a file with too few ("to assess a curve").
  std::string_view purpose = "to assess a curve";
  /// Checks the header (or, without one, the first row's width) before any data row is read,
  /// so a wrong layout is reported before the rows it makes look wrong. `line` is the 1-based
  /// line of that row. Throws InputError (see CsvLocation) to refuse it.
  std::function<void(const CsvTable& table, std::size_t line)> check_layout;
};

/// Reads and checks `path`: every cell a finite number, every row as wide as the header, time
/// ordered as `rules` asks, at least two rows. Separator ',', ';' or tab (taken from the header
/// line), quoted header names, a UTF-8 byte order mark, '#' comment lines and blank lines are
/// accepted; the header is optional unless rules.check_layout asks for one. A line longer than
/// kMaxCsvLineBytes or a row of more than kMaxCsvCells cells is refused as soon as it is met:
/// the file is read line by line, never whole. Throws InputError naming file, line and column.
[[nodiscard]] CsvTable ReadCsv(const std::string& path, const CsvRules& rules = {});

/// As ReadCsv, on text already in memory; `path` only names the source in messages.
[[nodiscard]] CsvTable ParseCsv(std::string_view text, const std::string& path,
                                const CsvRules& rules = {});

/// "FILE:LINE:COL" (COL 1-based), the start of every message about a place in a CSV file.
[[nodiscard]] std::string CsvLocation(std::string_view path, std::size_t line,
                                      std::size_t column);

/// The shortest text that reads back as `value` ("0.1", "1e-07"), to quote a cell in messages.
[[nodiscard]] std::string NumberText(double value);

/// Finds a column by exact header name, else by 1-based index ("3"). Time (column 1) is
/// refused. Returns the 0-based column. `flag` names the option in messages. Throws InputError.
[[nodiscard]] std::size_t ResolveColumn(const CsvTable& table, const std::string& selector,
                                        std::string_view flag);

}  // namespace hiltwin::analysis
