// CSV reading: the formats accepted and every bad input named by file, line and column.
#include "hiltwin/analysis/csv.h"

#include <gtest/gtest.h>

#include <string>

namespace hiltwin::analysis {
namespace {

// Expects ParseCsv to fail with a message that contains every one of `parts`.
void ExpectError(const std::string& text, std::initializer_list<std::string> parts) {
  try {
    (void)ParseCsv(text, "in.csv");
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
  ExpectError("time,a\n0,1\n0.5,2\n0.25,3\n", {"in.csv:4:1", "goes backwards", "line 3"});
}

TEST(Csv, NeedsTwoSamplesAndTwoColumns) {
  ExpectError("time,a\n0,1\n", {"in.csv:2", "1 data row", "at least two"});
  ExpectError("time,a\n", {"in.csv", "0 data rows"});
  ExpectError("", {"in.csv", "empty file"});
  ExpectError("time\n0\n1\n", {"in.csv:1", "one column"});
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
