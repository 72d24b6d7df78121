#pragma once
/// Files of named numbers in TOML, read into a struct of doubles: the one loader behind
/// relbot.toml (relbot_params.h) and ecs_gains.toml (ecs_gains.h). A spec table lists every
/// key in file order, the member its value goes to and its range. Every key is required,
/// unknown tables and keys are rejected (a typo must not silently fall back to a built-in
/// value), every value must be a finite number in its range, and every error is a ConfigError
/// "file:line:column: what is wrong; what to do" (the line and column where known).
///
/// The templates only map between the record and an array of doubles; the parsing and every
/// message live once, in toml_numbers.cpp, so this header does not pull in the TOML library.

#include <array>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <string_view>

namespace hiltwin::app {

/// `max` of a number without an upper limit: its range then reads "> min" or ">= min" alone.
inline constexpr double kTomlNoUpperLimit = std::numeric_limits<double>::infinity();

/// How one number appears in the file and which values it accepts.
template <class Record>
struct TomlNumberSpec {
  std::string_view table;            ///< TOML table, e.g. "motor"
  std::string_view key;              ///< key in the table, e.g. "resistance_ohm"
  double Record::*member = nullptr;  ///< where the value goes
  double min = 0.0;                  ///< smallest accepted value
  bool min_exclusive = false;        ///< true: value must be > min; false: >= min
  double max = kTomlNoUpperLimit;    ///< largest accepted value (inclusive), or no limit
};

/// The words one file's messages are made of. For the RELbot parameters, e.g.:
///   "<source>: missing <value_name> motor.resistance_ohm (a number > 0 and <= 10000); add it
///    under [motor]; fix it in the file (<file_hint>), or <fallback>"
///   "<source>:40:1: unknown table [battery]; expected the tables <expected_tables>; fix it ..."
///   "<path>: cannot read the <file_name> (<errno text>); check the path, or <fallback>"
struct TomlNumbersWording {
  std::string_view value_name;       ///< what one value is called: "RELbot parameter"
  std::string_view file_name;        ///< what the file is called: "RELbot parameter file"
  std::string_view expected_tables;  ///< the tables, as a phrase: "pid and output"
  std::string_view file_hint;        ///< where the documented file is and what it shows
  std::string_view fallback;         ///< how to do without a file: "run without a ... file ..."
};

/// A spec without its record type: what the parser and the messages need.
struct TomlNumberRule {
  std::string_view table;
  std::string_view key;
  double min = 0.0;
  bool min_exclusive = false;
  double max = kTomlNoUpperLimit;
};

// The record-free core (toml_numbers.cpp); values[i] belongs to rules[i].
namespace detail {

/// Parses the text, rejects unknown tables and keys, reads every rule's number into values.
void ParseTomlNumbers(std::string_view toml_text, std::string_view source_name,
                      std::span<const TomlNumberRule> rules, const TomlNumbersWording& wording,
                      std::span<double> values);
/// Throws ConfigError for the first value that is not finite or out of its rule's range.
void ValidateTomlNumbers(std::span<const TomlNumberRule> rules, std::span<const double> values,
                         std::string_view source_name, const TomlNumbersWording& wording);
/// The file's text; throws ConfigError with the errno text when it cannot be read.
std::string ReadTomlFile(const std::filesystem::path& path, const TomlNumbersWording& wording);

/// The specs without their member pointers.
template <class Record, std::size_t N>
constexpr std::array<TomlNumberRule, N> RulesOf(
    const std::array<TomlNumberSpec<Record>, N>& specs) noexcept {
  std::array<TomlNumberRule, N> rules{};
  for (std::size_t i = 0; i < N; ++i) {
    rules[i] = {specs[i].table, specs[i].key, specs[i].min, specs[i].min_exclusive, specs[i].max};
  }
  return rules;
}

}  // namespace detail

/// Checks every value of `record` is finite and within its range; throws ConfigError naming
/// `source_name` and the key ("table.key"). Does not allocate unless it throws.
template <class Record, std::size_t N>
void ValidateTomlNumbers(const Record& record, std::string_view source_name,
                         const std::array<TomlNumberSpec<Record>, N>& specs,
                         const TomlNumbersWording& wording) {
  std::array<double, N> values{};
  for (std::size_t i = 0; i < N; ++i) values[i] = record.*specs[i].member;
  detail::ValidateTomlNumbers(detail::RulesOf(specs), values, source_name, wording);
}

/// Parses TOML text into a record whose every spec'd member comes from the text. Throws
/// ConfigError with source_name:line:column where known.
template <class Record, std::size_t N>
[[nodiscard]] Record ParseTomlNumbers(std::string_view toml_text, std::string_view source_name,
                                      const std::array<TomlNumberSpec<Record>, N>& specs,
                                      const TomlNumbersWording& wording) {
  std::array<double, N> values{};
  detail::ParseTomlNumbers(toml_text, source_name, detail::RulesOf(specs), wording, values);
  Record record{};
  for (std::size_t i = 0; i < N; ++i) record.*specs[i].member = values[i];
  return record;
}

/// Reads and parses a file; throws ConfigError, also when it cannot be read.
template <class Record, std::size_t N>
[[nodiscard]] Record LoadTomlNumbers(const std::filesystem::path& path,
                                     const std::array<TomlNumberSpec<Record>, N>& specs,
                                     const TomlNumbersWording& wording) {
  return ParseTomlNumbers(detail::ReadTomlFile(path, wording), path.string(), specs, wording);
}

}  // namespace hiltwin::app
