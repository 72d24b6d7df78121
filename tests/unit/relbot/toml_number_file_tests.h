#pragma once
// What every TOML number file (relbot/toml_numbers.h: relbot.toml, ecs_gains.toml) must do,
// written once as a type-parameterised suite. A file's own test instantiates it with a traits
// type that names the file's functions and the exact messages its users see:
//
//   struct File {
//     using Record = ...;                                // the struct the file fills
//     inline static const char* const kPath;             // the shipped file
//     static constexpr auto kParse, kLoad, kValidate;    // the file's public functions
//     static constexpr auto kSpecs, kDefaults;
//     static constexpr std::string_view kWhatToDo;       // every parse or validate error ends so
//     static constexpr std::string_view kExpectedTables; // "...; expected the tables <this>; ..."
//     static constexpr std::string_view kUnknownTable, kUnknownTopLevelKey;
//     static constexpr MissingKey kMissing;
//     static constexpr LineEdit kBelowMin, kAboveMax, kNotANumber, kUnknownKey;
//     static constexpr NonFiniteKey kNonFinite;
//     static constexpr IntegerKey<Record> kInteger;
//     static constexpr double Record::*kValidateMember;  // set to NaN, Validate must name it
//     static constexpr std::string_view kValidateNaN;
//     static constexpr std::string_view kUnreadable;     // after "<path>: "
//   };
//
// Include this header from one source file per test executable.

#include <gtest/gtest.h>

#include <cctype>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

#include "hiltwin/relbot/config_error.h"

namespace hiltwin::app {
namespace toml_test {

/// The source name the suite parses under; messages start with it.
inline constexpr std::string_view kSource = "test.toml";

/// A key removed from the file, and the message (before "; <what to do>").
struct MissingKey {
  std::string_view key;
  std::string_view message;
};

/// The first line that starts with "key =" replaced by `replacement`, and the message that
/// must follow "test.toml:<that line>:<column>: " (before "; <what to do>").
struct LineEdit {
  std::string_view key;
  std::string_view replacement;
  std::string_view message;
};

/// A key set to nan, inf and -inf in turn, and the message each must give.
struct NonFiniteKey {
  std::string_view key;
  std::string_view message;
};

/// A key written as the integer `value`, which must land in `member` as that number.
template <class Record>
struct IntegerKey {
  std::string_view key;
  double Record::*member;
  int value;
};

inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Replaces the first line that starts with `key =` by `replacement`; returns its 1-based
/// number (0: no such line), so tests can expect "file:line:" in the message.
inline int ReplaceLine(std::string& text, std::string_view key, std::string_view replacement) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  int number = 0;
  int found = 0;
  while (std::getline(in, line)) {
    ++number;
    if (found == 0 && line.starts_with(std::string(key) + " =")) {
      found = number;
      line = replacement;
    }
    out << line << '\n';
  }
  text = out.str();
  return found;
}

/// The ConfigError `parse` throws for `text` (parsed as kSource), or "(no error)".
template <class Parse>
std::string ErrorOf(Parse parse, const std::string& text) {
  try {
    (void)parse(text, kSource);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

/// `message` with the column of "test.toml:<line>:<column>:" taken out, so a test can compare
/// the whole message without depending on where the TOML library puts the column.
inline std::string WithoutColumn(const std::string& message) {
  const std::string prefix = std::string(kSource) + ":";
  if (!message.starts_with(prefix)) return message;
  const std::size_t line_end = message.find(':', prefix.size());
  if (line_end == std::string::npos) return message;
  std::size_t column_end = line_end + 1;
  while (column_end < message.size() &&
         std::isdigit(static_cast<unsigned char>(message[column_end])))
    ++column_end;
  if (column_end == line_end + 1 || column_end >= message.size() || message[column_end] != ':')
    return message;
  return message.substr(0, line_end) + message.substr(column_end);
}

/// "test.toml:<line>: <message>; <what_to_do>": what WithoutColumn leaves of a located error.
inline std::string AtLine(int line, std::string_view message, std::string_view what_to_do) {
  return std::string(kSource) + ":" + std::to_string(line) + ": " + std::string(message) + "; " +
         std::string(what_to_do);
}

inline int LineCount(const std::string& text) {
  int lines = 0;
  for (const char c : text) lines += c == '\n' ? 1 : 0;
  return lines;
}

}  // namespace toml_test

template <class File>
class TomlNumberFile : public ::testing::Test {
 protected:
  static std::string Text() { return toml_test::ReadFile(File::kPath); }
  static std::string ErrorOf(const std::string& text) {
    return toml_test::ErrorOf(File::kParse, text);
  }
  /// Applies `edit` to the shipped file; the error must be edit.message at the edited line.
  static void ExpectLocatedError(const toml_test::LineEdit& edit) {
    SCOPED_TRACE(edit.replacement);
    std::string text = Text();
    const int line = toml_test::ReplaceLine(text, edit.key, edit.replacement);
    ASSERT_GT(line, 0) << "no line starts with " << edit.key << " =";
    EXPECT_EQ(toml_test::WithoutColumn(ErrorOf(text)),
              toml_test::AtLine(line, edit.message, File::kWhatToDo));
  }
};

TYPED_TEST_SUITE_P(TomlNumberFile);

TYPED_TEST_P(TomlNumberFile, ShippedFileEqualsBuiltInDefaults) {
  using Record = typename TypeParam::Record;
  const Record from_file = TypeParam::kLoad(TypeParam::kPath);
  const Record defaults = TypeParam::kDefaults();
  std::size_t compared = 0;
  for (const auto& spec : TypeParam::kSpecs()) {
    EXPECT_EQ(from_file.*spec.member, defaults.*spec.member) << spec.table << "." << spec.key;
    ++compared;
  }
  // Every member of the record is in the file: no value escapes it.
  EXPECT_EQ(compared * sizeof(double), sizeof(Record));
}

TYPED_TEST_P(TomlNumberFile, DefaultsAreValid) {
  EXPECT_NO_THROW(TypeParam::kValidate(TypeParam::kDefaults(), "built-in"));
}

TYPED_TEST_P(TomlNumberFile, MissingKeyIsNamedWithItsTable) {
  std::string text = this->Text();
  ASSERT_GT(toml_test::ReplaceLine(text, TypeParam::kMissing.key, "# removed"), 0);
  EXPECT_EQ(this->ErrorOf(text), std::string(toml_test::kSource) + ": " +
                                     std::string(TypeParam::kMissing.message) + "; " +
                                     std::string(TypeParam::kWhatToDo));
}

TYPED_TEST_P(TomlNumberFile, OutOfRangeValueIsNamedWithLineAndRange) {
  this->ExpectLocatedError(TypeParam::kBelowMin);
  this->ExpectLocatedError(TypeParam::kAboveMax);
}

TYPED_TEST_P(TomlNumberFile, NonFiniteValuesAreRejected) {
  for (const std::string_view value : {"nan", "inf", "-inf"}) {
    // Appended, not `a + " = " + b`: g++ 12 reports a false -Warray-bounds on that
    // temporary's copy when this test is inlined beside others (a unity build).
    std::string replacement(TypeParam::kNonFinite.key);
    replacement.append(" = ").append(value);
    this->ExpectLocatedError(
        {TypeParam::kNonFinite.key, replacement, TypeParam::kNonFinite.message});
  }
}

TYPED_TEST_P(TomlNumberFile, NonNumberIsRejected) {
  this->ExpectLocatedError(TypeParam::kNotANumber);
}

TYPED_TEST_P(TomlNumberFile, IntegersAreAcceptedAsNumbers) {
  const auto& integer = TypeParam::kInteger;
  std::string text = this->Text();
  ASSERT_GT(
      toml_test::ReplaceLine(text, integer.key,
                             std::string(integer.key) + " = " + std::to_string(integer.value)),
      0);
  EXPECT_EQ(TypeParam::kParse(text, toml_test::kSource).*integer.member,
            static_cast<double>(integer.value));
}

TYPED_TEST_P(TomlNumberFile, UnknownKeyIsNamedWithLine) {
  this->ExpectLocatedError(TypeParam::kUnknownKey);
}

TYPED_TEST_P(TomlNumberFile, UnknownTableAndTopLevelKeyAreRejected) {
  const std::string expected = "; expected the tables " + std::string(TypeParam::kExpectedTables) +
                               "; " + std::string(TypeParam::kWhatToDo);
  const std::string text = this->Text();
  const std::string table(TypeParam::kUnknownTable);
  EXPECT_EQ(toml_test::WithoutColumn(this->ErrorOf(text + "[" + table + "]\nx = 1.0\n")),
            std::string(toml_test::kSource) + ":" + std::to_string(toml_test::LineCount(text) + 1) +
                ": unknown table [" + table + "]" + expected);
  const std::string key(TypeParam::kUnknownTopLevelKey);
  EXPECT_EQ(toml_test::WithoutColumn(this->ErrorOf(key + " = 3\n" + text)),
            std::string(toml_test::kSource) + ":1: unknown top-level key '" + key + "'" + expected);
}

TYPED_TEST_P(TomlNumberFile, SyntaxErrorGivesLineAndColumn) {
  std::string text = this->Text();
  const std::string_view key = TypeParam::kSpecs().front().key;
  const int line = toml_test::ReplaceLine(text, key, std::string(key) + " = = 1.0");
  ASSERT_GT(line, 0);
  const std::string message = this->ErrorOf(text);
  const std::string located = toml_test::WithoutColumn(message);
  EXPECT_NE(located, message) << "no column in: " << message;
  EXPECT_TRUE(located.starts_with(std::string(toml_test::kSource) + ":" + std::to_string(line) +
                                  ": not valid TOML: "))
      << message;
  EXPECT_TRUE(located.ends_with("; " + std::string(TypeParam::kWhatToDo))) << message;
}

TYPED_TEST_P(TomlNumberFile, UnreadableFileSaysSo) {
  const std::string path =
      "/nonexistent/" + std::filesystem::path(TypeParam::kPath).filename().string();
  try {
    (void)TypeParam::kLoad(path);
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()), path + ": " + std::string(TypeParam::kUnreadable));
  }
}

TYPED_TEST_P(TomlNumberFile, ValidateNamesTheSourceAndTheKey) {
  auto record = TypeParam::kDefaults();
  record.*TypeParam::kValidateMember = std::numeric_limits<double>::quiet_NaN();
  try {
    TypeParam::kValidate(record, "built-in");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()), "built-in: " + std::string(TypeParam::kValidateNaN) +
                                             "; " + std::string(TypeParam::kWhatToDo));
  }
}

REGISTER_TYPED_TEST_SUITE_P(TomlNumberFile, ShippedFileEqualsBuiltInDefaults, DefaultsAreValid,
                            MissingKeyIsNamedWithItsTable, OutOfRangeValueIsNamedWithLineAndRange,
                            NonFiniteValuesAreRejected, NonNumberIsRejected,
                            IntegersAreAcceptedAsNumbers, UnknownKeyIsNamedWithLine,
                            UnknownTableAndTopLevelKeyAreRejected, SyntaxErrorGivesLineAndColumn,
                            UnreadableFileSaysSo, ValidateNamesTheSourceAndTheKey);

}  // namespace hiltwin::app
