// The log readers of the analysis module: ParseCsv (curves for `hiltwin assess`, any hiltwin
// CSV log; tracing/csv.h, documents InputError) and ReadTimingLog (`hiltwin trace --analyze
// FILE` on a `--timing-log`; traces/trace_readers.h, documents TraceReadError).
//
// Input: byte 0 chooses the reader (0: ParseCsv for curves, 1: ParseCsv for signal knots with
// a layout check that wants a header, 2 and 3: ReadTimingLog); the rest is the file.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "hiltwin/traces/trace_readers.h"
#include "hiltwin/tracing/csv.h"

namespace {

using namespace hiltwin::analysis;

void ReadCsvText(std::string_view text, bool knots) {
  CsvRules rules;
  if (knots) {
    rules.time_order = TimeOrder::kStepsAllowed;
    rules.purpose = "to fuzz a profile";
    rules.check_layout = [](const CsvTable& table, std::size_t line) {
      if (!table.has_header) throw InputError(CsvLocation(table.path, line, 1) + ": no header");
    };
  }
  const CsvTable table = ParseCsv(text, "fuzz.csv", rules);
  // Every message helper on what was accepted.
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    (void)table.ColumnLabel(c);
    if (table.rows() > 0) (void)table.Where(table.rows() - 1, c);
  }
  if (table.columns.size() > 1) (void)ResolveColumn(table, "2", "--column");
  if (!table.names.empty()) (void)ResolveColumn(table, table.names.back(), "--column");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const unsigned mode = data[0] & 3U;
  if (mode < 2) {
    try {
      ReadCsvText(hiltwin::fuzz::AsText(data + 1, size - 1), mode == 1);
    } catch (const InputError&) {
    }
    HILTWIN_FUZZ_UNDOCUMENTED("ParseCsv")
  } else {
    const std::string path = hiltwin::fuzz::WriteScratch("timing.csv", data + 1, size - 1);
    try {
      (void)ReadTimingLog(path);
    } catch (const TraceReadError&) {
    }
    HILTWIN_FUZZ_UNDOCUMENTED("ReadTimingLog")
  }
  return 0;
}
