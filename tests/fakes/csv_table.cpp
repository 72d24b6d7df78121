#include "fakes/csv_table.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace hiltwin::test {

std::map<std::string, double> CsvTable::LastRow() const {
  std::map<std::string, double> row;
  if (rows.empty()) return row;
  for (std::size_t i = 0; i < columns.size() && i < rows.back().size(); ++i) {
    row[columns[i]] = rows.back()[i];
  }
  return row;
}

CsvTable ReadCsvTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  CsvTable table;
  std::string line;
  if (std::getline(in, line)) {
    std::stringstream header(line);
    for (std::string cell; std::getline(header, cell, ',');) table.columns.push_back(cell);
  }
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::vector<double> row;
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace hiltwin::test
