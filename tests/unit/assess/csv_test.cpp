// CSV reading: the formats accepted and every bad input named by file, line and column.
#include "hiltwin/tracing/csv.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace hiltwin::analysis {
namespace {

// Expects ParseCsv (with `rules`) to fail with a message that contains every one of `parts`.
void ExpectError(const std::string& text, std::initializer_list<std::string> parts,
                 const CsvRules& rules = {}) {
  try {
    (void)ParseCsv(text, "in.csv", rules);
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

TEST(Csv, Reads20simSaveDataToFileLayout) {
  // 20-sim quotes its header names, which may hold backslashes and spaces.
  const CsvTable t = ParseCsv(
      "\"time\",\"plant\\position right\",\"DT position\"\r\n0,0,0\r\n0.001,0.5,0.49\r\n", "s.csv");
  ASSERT_EQ(t.names.size(), 3u);
  EXPECT_EQ(t.names[1], "plant\\position right");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.columns[2][1], 0.49);
  EXPECT_EQ(t.lines[1], 3u);
  EXPECT_EQ(ResolveColumn(t, "DT position", "--exp"), 2u);
  EXPECT_EQ(ResolveColumn(t, "2", "--sim"), 1u);
}

TEST(Csv, AcceptsSemicolonsTabsCommentsBlankLinesAndNoHeader) {
  const CsvTable semi = ParseCsv("# hiltwin log\ntime;a;b\n\n0;1;2\n1;+3;4e-1\n", "x.csv");
  EXPECT_EQ(semi.header_line, 2u);
  EXPECT_DOUBLE_EQ(semi.columns[1][1], 3.0);
  EXPECT_DOUBLE_EQ(semi.columns[2][1], 0.4);
  const CsvTable tabs = ParseCsv("t\ty\n0\t1\n1\t2\n", "x.csv");
  EXPECT_EQ(tabs.names[1], "y");
  const CsvTable bare = ParseCsv("0,1,2\n1,3,4\n", "x.csv");
  EXPECT_FALSE(bare.has_header);
  EXPECT_EQ(bare.rows(), 2u);
  EXPECT_EQ(ResolveColumn(bare, "3", "--exp"), 2u);
}

TEST(Csv, Utf8ByteOrderMarkIsSkipped) {
  // "CSV UTF-8" from Excel starts with EF BB BF; the first name must still be "time".
  const CsvTable t = ParseCsv("\xEF\xBB\xBFtime,sim,exp\n0,1,2\n1,2,3\n", "bom.csv");
  ASSERT_EQ(t.names.size(), 3u);
  EXPECT_EQ(t.names[0], "time");
  EXPECT_EQ(ResolveColumn(t, "sim", "--sim"), 1u);
  EXPECT_EQ(t.lines[0], 2u);
  const CsvTable bare = ParseCsv("\xEF\xBB\xBF" "0,1\n1,2\n", "bom.csv");  // no header
  EXPECT_FALSE(bare.has_header);
  EXPECT_DOUBLE_EQ(bare.columns[0][0], 0.0);
  EXPECT_EQ(bare.rows(), 2u);
}

TEST(Csv, NonNumericCellNamesFileLineColumn) {
  ExpectError("time,a,b\n0,1,2\n1,abc,3\n", {"in.csv:3:2", "'a'", "'abc' is not a number"});
  ExpectError("time,a,b\n0,1,2\n1,,3\n", {"in.csv:3:2", "empty cell"});
  ExpectError("time,a,b\n0,1,2\n1,2,3,5 ; 4\n", {"in.csv:3", "4 cells"});
}

TEST(Csv, NanAndInfNameFileLineColumn) {
  ExpectError("time,a,b\n0,1,2\n1,2,nan\n", {"in.csv:3:3", "NaN or Inf"});
  ExpectError("time,a,b\n0,1,2\n1,inf,3\n", {"in.csv:3:2", "NaN or Inf"});
  ExpectError("time,a,b\n0,1,2\n1,1e999,3\n", {"in.csv:3:2", "NaN or Inf"});
}

TEST(Csv, TimeMustStrictlyIncrease) {
  ExpectError("time,a\n0,1\n0.5,2\n0.5,3\n", {"in.csv:4:1", "repeats", "strictly increasing"});
  ExpectError("time,a\n0,1\n0.5,2\n0.25,3\n",
              {"in.csv:4:1", "time 0.25 s is earlier than the previous row's 0.5 s (line 3)"});
  // Times are quoted as written, not rounded to six decimals (1 MHz logs stay readable).
  ExpectError("time,a\n0,1\n2e-7,2\n1e-7,3\n", {"time 1e-07 s", "row's 2e-07 s"});
}

TEST(Csv, StepsAllowedTakesTwoRowsPerTimeButNotThree) {
  CsvRules steps;
  steps.time_order = TimeOrder::kStepsAllowed;
  const CsvTable t = ParseCsv("time,u\n0,0\n1,0\n1,1\n2,1\n", "s.csv", steps);
  EXPECT_EQ(t.rows(), 4u);
  try {
    (void)ParseCsv("time,u\n0,0\n1,0\n1,1\n1,2\n", "s.csv", steps);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.csv:5:1: time 1 s is on a third row (lines 3, 4 and 5)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)ParseCsv("time,u\n0,0\n1,0\n0.5,1\n", "s.csv", steps), InputError);
}

TEST(Csv, LayoutCheckRunsBeforeAnyDataRow) {
  CsvRules rules;
  std::size_t seen_line = 0;
  rules.check_layout = [&seen_line](const CsvTable& table, std::size_t line) {
    seen_line = line;
    if (table.names.size() != 3) throw InputError(CsvLocation(table.path, line, 1) + ": want 3");
  };
  // The bad row 3 would fail on its own; the layout check must speak first.
  ExpectError("time,a\n0,1\n1,x\n", {"in.csv:1:1: want 3"}, rules);
  EXPECT_THROW((void)ParseCsv("# c\ntime,a\n0,1\n1,x\n", "in.csv", rules), InputError);
  EXPECT_EQ(seen_line, 2u);
  EXPECT_EQ(ParseCsv("time,a,b\n0,1,2\n1,2,3\n", "in.csv", rules).rows(), 2u);
}

TEST(Csv, RowOfTheWrongWidthPointsAtTheFirstMissingOrExtraCell) {
  ExpectError("time,a,b\n0,1,2\n1,2\n", {"in.csv:3:3:", "row has 2 cells but the header has 3"});
  ExpectError("0,1\n1,2,3\n", {"in.csv:2:3:", "row has 3 cells but the first row has 2"});
}

TEST(Csv, NumberTextIsShortestAndExact) {
  EXPECT_EQ(NumberText(0.1), "0.1");
  EXPECT_EQ(NumberText(2.0), "2");
  EXPECT_EQ(NumberText(1.50000001), "1.50000001");
  EXPECT_EQ(NumberText(-1e-7), "-1e-07");
}

TEST(Csv, NeedsTwoSamplesAndTwoColumns) {
  ExpectError("time,a\n0,1\n", {"in.csv:2", "1 data row", "at least two"});
  ExpectError("time,a\n", {"in.csv", "0 data rows"});
  ExpectError("", {"in.csv:1:1", "empty file"});
  ExpectError("time\n0\n1\n", {"in.csv:1:2", "one column"});
  ExpectError("0\n1\n", {"in.csv:1:2", "the first row has one column"});
}

TEST(Csv, UnknownOrTimeColumnIsRefusedWithTheChoices) {
  const CsvTable t = ParseCsv("time,sim,exp\n0,1,2\n1,2,3\n", "in.csv");
  try {
    (void)ResolveColumn(t, "position", "--exp");
    ADD_FAILURE();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("in.csv:1"), std::string::npos) << m;
    EXPECT_NE(m.find("--exp 'position'"), std::string::npos) << m;
    EXPECT_NE(m.find("2='sim'"), std::string::npos) << m;
  }
  EXPECT_THROW((void)ResolveColumn(t, "1", "--sim"), InputError);
  EXPECT_THROW((void)ResolveColumn(t, "time", "--sim"), InputError);
  EXPECT_THROW((void)ResolveColumn(t, "4", "--sim"), InputError);
  EXPECT_THROW((void)ResolveColumn(t, "0", "--sim"), InputError);
}

// A file of the test's own, removed at the end.
class CsvFile : public ::testing::Test {
 protected:
  void TearDown() override { std::filesystem::remove(path_); }
  [[nodiscard]] const std::string& Write(const std::string& text) {
    std::ofstream(path_, std::ios::binary) << text;
    return path_;
  }
  std::string path_ = (std::filesystem::temp_directory_path() /
                       ("hiltwin_csv_test_" + std::to_string(::getpid()) + ".csv"))
                          .string();
};

std::string ReadError(const std::string& path) {
  try {
    (void)ReadCsv(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// A line one byte over the cap (a file without line breaks, say) is refused at that line as
// soon as the cap is passed, from a file and from text alike; a line of exactly the cap is read.
TEST_F(CsvFile, ALineLongerThanTheCapIsRefusedAtOnceWithItsLine) {
  const std::size_t cap = kMaxCsvLineBytes;
  std::string over = "time,a\n0,1\n1,";
  over += std::string(cap + 1 - 2, '0');  // line 3: "1," and then zeros, cap + 1 bytes
  over += "\n2,3\n";
  const std::string expected = ":3: the line is longer than 65536 bytes, the most hiltwin "
                               "reads as one CSV row";
  const std::string from_file = ReadError(Write(over));
  EXPECT_EQ(from_file.rfind(path_ + expected, 0), 0U) << from_file;
  ExpectError(over, {"in.csv" + expected, "one row per line"});
  std::string at_cap = "time,a\n0,1\n1,";
  at_cap += std::string(cap - 2, '0') + "\n";
  const CsvTable table = ReadCsv(Write(at_cap));
  EXPECT_EQ(table.rows(), 2U);
}

// An endless file without a line break (/dev/zero) is refused once the cap is passed: the
// reader holds one line at most, never the whole file.
TEST(Csv, AnEndlessLineIsRefusedAfterTheCap) {
  try {
    (void)ReadCsv("/dev/zero");
    ADD_FAILURE() << "/dev/zero read as a CSV";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/dev/zero:1: the line is longer than", 0), 0U)
        << e.what();
  }
}

// More cells in one row than the cap: refused with the line and the cell past the cap.
TEST(Csv, MoreCellsThanTheCapAreRefused) {
  std::string header = "time";
  for (std::size_t c = 1; c < kMaxCsvCells; ++c) header += ",c" + std::to_string(c);
  std::string zeros = "0";
  for (std::size_t c = 1; c < kMaxCsvCells; ++c) zeros += ",0";
  const CsvTable at_cap =
      ParseCsv(header + "\n" + zeros + "\n1" + zeros.substr(1) + "\n", "w.csv");
  EXPECT_EQ(at_cap.columns.size(), kMaxCsvCells);
  ExpectError(header + ",one_more\n" + zeros + ",0\n",
              {"in.csv:1:1025: the row has more than 1024 cells", "keep the time column"});
}

TEST(Csv, MissingFileSaysSo) {
  try {
    (void)ReadCsv("/nonexistent/dir/run.csv");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/run.csv: cannot open"), std::string::npos);
  }
}

}  // namespace
}  // namespace hiltwin::analysis
