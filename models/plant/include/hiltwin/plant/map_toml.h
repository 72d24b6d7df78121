#pragma once
/// The TOML reading that plant maps (plant_map.h) and controller maps (controller/
/// controller_map.h) share: places as file:line:column, refusal of unknown keys, one entry's
/// keys read with the entry's name in every message, board channels, the encoder scale from
/// counts_per_unit or counts_per_rev + gear_ratio (+ wheel_radius_m), [inputs] constants. Each
/// map's parser catches MapTomlError and throws its own error type with the same message.

#include <toml++/toml.h>

#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hiltwin/plant/plant_map.h"

namespace hiltwin::plant::map_toml {

/// A refusal with its place and what to do; the map's parser rethrows it as its own error.
class MapTomlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "source:line:column" (line and column left out when unknown).
[[nodiscard]] std::string Where(std::string_view source, const toml::source_region& region);
/// "source:line:column" from a line and column (0: unknown).
[[nodiscard]] std::string Where(std::string_view source, int line, int column);
[[noreturn]] void Fail(std::string_view source, const toml::node& at, const std::string& what);
/// A number as a message shows it (shortest of six significant digits).
[[nodiscard]] std::string Num(double value);

/// The text of `toml_text` as a table; invalid TOML is refused with its place.
[[nodiscard]] toml::table ParseRoot(std::string_view toml_text, std::string_view source);
/// A map file's text. An unreadable file is refused naming it, why, and `what_to_do`.
[[nodiscard]] std::string ReadMapFile(const std::filesystem::path& path,
                                      std::string_view map_name, std::string_view what_to_do);

/// Refuses keys a table does not know, so a typo cannot silently fall back to a default.
void CheckKeys(std::string_view source, const toml::table& table, std::string_view table_name,
               std::initializer_list<std::string_view> known);

/// `key` as an array of tables ([[key]]), or nullptr when absent; anything else is refused.
[[nodiscard]] const toml::array* ArrayOfTables(std::string_view source, const toml::table& root,
                                               std::string_view key);

/// Reads a table's entries one key at a time, with the entry's name in every message.
class Entry {
 public:
  Entry(std::string_view source, const toml::table& table, std::string name)
      : source_(source), table_(table), name_(std::move(name)) {}

  /// `channel`, required: an integer 1..4.
  [[nodiscard]] int Channel() const;
  [[nodiscard]] std::string String(std::string_view key, bool required) const;
  [[nodiscard]] std::optional<double> Number(std::string_view key) const;
  /// A scale that must be >= 0: the direction is `reverse`'s, so a negative one is refused.
  [[nodiscard]] std::optional<double> Scale(std::string_view key) const;
  /// A number that must be > 0 when given; 0 when absent.
  [[nodiscard]] double Positive(std::string_view key) const;
  [[nodiscard]] bool Flag(std::string_view key) const;
  /// Line and column of `key`'s value (the table's when it is missing), for later messages.
  [[nodiscard]] std::pair<int, int> Place(std::string_view key) const;
  /// "m" or "rad", required: what an encoder measures.
  [[nodiscard]] std::string EncoderUnit() const;
  /// Counts per unit (m or rad) of an encoder entry: counts_per_unit, or counts_per_rev with
  /// gear_ratio (and wheel_radius_m for "m"); one of the two, > 0, at most kMaxCountsPerUnit.
  [[nodiscard]] double EncoderScale(const std::string& unit) const;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const toml::table& table() const { return table_; }
  [[noreturn]] void Fail(std::string_view key, const std::string& what) const;

 private:
  [[nodiscard]] double Representable(const toml::node& at, const std::string& unit,
                                     double counts_per_unit) const;

  std::string_view source_;
  const toml::table& table_;
  std::string name_;
};

/// [inputs]: name = finite number, in file order.
[[nodiscard]] std::vector<ConstantInput> ParseConstants(std::string_view source,
                                                        const toml::table& root);

/// `parse()`, with a MapTomlError turned into the map's own `Error` with the same message.
template <class Error, class Fn>
auto Rethrown(Fn&& parse) -> decltype(parse()) {
  try {
    return parse();
  } catch (const MapTomlError& e) {
    throw Error(e.what());
  }
}

/// The index of the port called `name`, if any (both binders resolve names with it).
[[nodiscard]] std::optional<std::size_t> PortIndex(const std::vector<Port>& ports,
                                                   const std::string& name);
/// "a, b, c", or "none": the ports a message lists as what exists instead.
[[nodiscard]] std::string PortNames(const std::vector<Port>& ports);

/// One board channel carries one signal per direction. `tables` are the routes' own, for the
/// place of the second `channel`.
template <class Route>
void CheckChannelsOnce(std::string_view source, const toml::array* tables,
                       const std::vector<Route>& routes, std::string_view what) {
  std::set<int> seen;
  for (std::size_t i = 0; i < routes.size(); ++i) {
    if (seen.insert(routes[i].channel).second) continue;
    Fail(source, *(*tables)[i].as_table()->get("channel"),
         std::string(what) + " channel " + std::to_string(routes[i].channel) +
             " is mapped twice: a channel carries one signal");
  }
}

}  // namespace hiltwin::plant::map_toml
