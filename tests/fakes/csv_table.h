#pragma once
// A CSV log as the tests read it: the header's column names and the rows as numbers.

#include <map>
#include <string>
#include <vector>

namespace hiltwin::test {

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  /// The last row as column -> value (empty when there is no row).
  [[nodiscard]] std::map<std::string, double> LastRow() const;
};

/// Reads `path` (first line: header); throws std::runtime_error when it cannot be opened.
[[nodiscard]] CsvTable ReadCsvTable(const std::string& path);

}  // namespace hiltwin::test
