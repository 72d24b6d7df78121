#include "hiltwin/relbot/toml_numbers.h"

#include <toml++/toml.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "hiltwin/relbot/config_error.h"

namespace hiltwin::app::detail {
namespace {

using Rules = std::span<const TomlNumberRule>;

std::string FullKey(const TomlNumberRule& rule) {
  return std::string(rule.table) + "." + std::string(rule.key);
}

std::string Where(std::string_view source_name, const toml::source_region& region) {
  std::ostringstream out;
  out << source_name;
  if (region.begin.line != 0) out << ':' << region.begin.line << ':' << region.begin.column;
  return out.str();
}

std::string RangeText(const TomlNumberRule& rule) {
  std::ostringstream out;
  out << (rule.min_exclusive ? "> " : ">= ") << rule.min;
  if (rule.max < kTomlNoUpperLimit) out << " and <= " << rule.max;
  return out.str();
}

// Empty when the value is acceptable, otherwise why it is not.
std::string CheckValue(const TomlNumberRule& rule, double value) {
  if (!std::isfinite(value)) return "is not a finite number";
  const bool low = rule.min_exclusive ? !(value > rule.min) : !(value >= rule.min);
  if (low || value > rule.max) {
    std::ostringstream out;
    out << "= " << value << " is out of range: it must be " << RangeText(rule);
    return out.str();
  }
  return {};
}

bool IsKnownKey(Rules rules, std::string_view table, std::string_view key) {
  for (const TomlNumberRule& rule : rules) {
    if (rule.table == table && rule.key == key) return true;
  }
  return false;
}

bool IsKnownTable(Rules rules, std::string_view table) {
  for (const TomlNumberRule& rule : rules) {
    if (rule.table == table) return true;
  }
  return false;
}

// `what` (which starts with where it happened), then what to do about it.
ConfigError Error(const std::string& what, const TomlNumbersWording& wording) {
  return ConfigError(what + "; fix it in the file (" + std::string(wording.file_hint) + "), or " +
                     std::string(wording.fallback));
}

// "<value_name> table.key": how a message names one value.
std::string ValueName(const TomlNumberRule& rule, const TomlNumbersWording& wording) {
  return std::string(wording.value_name) + " " + FullKey(rule);
}

// Thread-safe (strerror is not, and libstdc++'s generic_category().message calls it); the same
// text as strerror. The GNU strerror_r may return a static string instead of filling `buffer`.
std::string ErrnoText(int error) {
  char buffer[256];
  return strerror_r(error, buffer, sizeof buffer);
}

toml::table ParseDocument(std::string_view toml_text, std::string_view source_name,
                          const TomlNumbersWording& wording) {
  try {
    return toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    throw Error(Where(source_name, error.source()) +
                    ": not valid TOML: " + std::string(error.description()),
                wording);
  }
}

// Unknown tables and keys are almost always typos (or a unit suffix changed by hand): ignoring
// them would run with the built-in value the user meant to change.
void RejectUnknownKeys(const toml::table& root, std::string_view source_name, Rules rules,
                       const TomlNumbersWording& wording) {
  for (const auto& [table_name, table_node] : root) {
    const toml::table* table = table_node.as_table();
    if (table == nullptr || !IsKnownTable(rules, table_name.str())) {
      throw Error(Where(source_name, table_node.source()) + ": unknown " +
                      (table == nullptr ? "top-level key '" : "table [") +
                      std::string(table_name.str()) + (table == nullptr ? "'" : "]") +
                      "; expected the tables " + std::string(wording.expected_tables),
                  wording);
    }
    for (const auto& [key, node] : *table) {
      if (!IsKnownKey(rules, table_name.str(), key.str())) {
        throw Error(Where(source_name, node.source()) + ": unknown key " +
                        std::string(table_name.str()) + "." + std::string(key.str()) +
                        " (check the spelling and the unit suffix)",
                    wording);
      }
    }
  }
}

double ReadValue(const toml::table& root, std::string_view source_name, const TomlNumberRule& rule,
                 const TomlNumbersWording& wording) {
  const toml::node* node = root[rule.table][rule.key].node();
  if (node == nullptr) {
    throw Error(std::string(source_name) + ": missing " + ValueName(rule, wording) + " (a number " +
                    RangeText(rule) + "); add it under [" + std::string(rule.table) + "]",
                wording);
  }
  const std::optional<double> value = node->value<double>();
  if (!node->is_number() || !value) {
    std::ostringstream type;
    type << node->type();
    throw Error(Where(source_name, node->source()) + ": " + ValueName(rule, wording) +
                    " must be a number, not a " + type.str(),
                wording);
  }
  const std::string why = CheckValue(rule, *value);
  if (!why.empty()) {
    throw Error(Where(source_name, node->source()) + ": " + ValueName(rule, wording) + " " + why,
                wording);
  }
  return *value;
}

}  // namespace

void ParseTomlNumbers(std::string_view toml_text, std::string_view source_name, Rules rules,
                      const TomlNumbersWording& wording, std::span<double> values) {
  const toml::table root = ParseDocument(toml_text, source_name, wording);
  RejectUnknownKeys(root, source_name, rules, wording);
  for (std::size_t i = 0; i < rules.size(); ++i) {
    values[i] = ReadValue(root, source_name, rules[i], wording);
  }
}

void ValidateTomlNumbers(Rules rules, std::span<const double> values, std::string_view source_name,
                         const TomlNumbersWording& wording) {
  for (std::size_t i = 0; i < rules.size(); ++i) {
    const std::string why = CheckValue(rules[i], values[i]);
    if (!why.empty()) {
      throw Error(std::string(source_name) + ": " + ValueName(rules[i], wording) + " " + why,
                  wording);
    }
  }
}

std::string ReadTomlFile(const std::filesystem::path& path, const TomlNumbersWording& wording) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    throw ConfigError(path.string() + ": cannot read the " + std::string(wording.file_name) + " (" +
                      ErrnoText(error) + "); check the path, or " + std::string(wording.fallback));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace hiltwin::app::detail
