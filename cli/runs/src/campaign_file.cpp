// `hiltwin test`'s campaign file (hiltwin/runs/campaign_file.h): the TOML tables read into
// typed scenarios. [defaults] and every [[scenario]] are read by the same functions, so a key
// means the same in both and a scenario starts from the defaults and overrides them key by key
// (its criteria too). What the keys mean together (a tracking bound on an open-loop scenario, a
// setpoint with no step for a settling bound) is checked after, in campaign_checks.cpp.
#include "hiltwin/runs/campaign_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "campaign_checks.h"
#include "hiltwin/plant/map_toml.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/setpoint_profile.h"

namespace hiltwin::app {
namespace campaign_file_reading {

namespace fs = std::filesystem;
namespace mt = plant::map_toml;

/// A table of the file being read, with the file's name and folder for messages and paths.
struct CampaignReader {
  std::string source;  ///< the file, as messages name it
  std::string folder;  ///< where relative paths are read from

  [[noreturn]] void Fail(const toml::node& at, const std::string& what) const {
    throw CampaignFileError(mt::Where(source, at.source()) + ": " + what);
  }

  std::string String(const toml::node& node, std::string_view key) const {
    if (!node.is_string()) Fail(node, std::string(key) + " must be a string");
    return node.value<std::string>().value_or("");
  }

  double Number(const toml::node& node, std::string_view key) const {
    const std::optional<double> value = node.value<double>();  // an integer reads as a double
    if (!value || !std::isfinite(*value)) Fail(node, std::string(key) + " must be a number");
    return *value;
  }

  /// A number >= min (or > min when exclusive).
  double Bound(const toml::node& node, std::string_view key, double min, bool exclusive) const {
    const double value = Number(node, key);
    if (exclusive ? value <= min : value < min) {
      Fail(node, std::string(key) + " = " + mt::Num(value) + ": must be " +
                     (exclusive ? "above " : "at least ") + mt::Num(min));
    }
    return value;
  }

  /// An array of flag strings, each given to `check` (which throws std::invalid_argument).
  std::vector<std::string> Flags(const toml::node& node, std::string_view key,
                                 void (*check)(const std::string&)) const {
    const toml::array* array = node.as_array();
    if (array == nullptr) Fail(node, std::string(key) + " must be an array of strings");
    std::vector<std::string> texts;
    for (const toml::node& item : *array) {
      texts.push_back(String(item, key));
      try {
        check(texts.back());
      } catch (const std::invalid_argument& e) {
        Fail(item, std::string(key) + ": " + e.what());
      }
    }
    return texts;
  }

  /// A file path, made absolute against the campaign's folder; "" stays "" (the default).
  std::string Path(const toml::node& node, std::string_view key) const {
    const std::string text = String(node, key);
    if (text.empty()) return text;
    return fs::absolute(fs::path(folder) / text).lexically_normal().string();
  }

  /// A profile: a built-in name stays as it is, anything else is a path.
  std::string Profile(const toml::node& node, std::string_view key,
                      std::span<const std::string_view> builtin) const {
    const std::string text = String(node, key);
    if (std::find(builtin.begin(), builtin.end(), text) != builtin.end()) return text;
    return Path(node, key);
  }

  /// A controller spec: lib: and fmu: name files, read from the campaign's folder.
  std::string Controller(const toml::node& node) const {
    const std::string text = String(node, "controller");
    for (const std::string_view prefix : {"lib:", "fmu:"}) {
      if (text.starts_with(prefix) && text.size() > prefix.size()) {
        return std::string(prefix) + (fs::absolute(fs::path(folder) / text.substr(prefix.size())))
                                         .lexically_normal()
                                         .string();
      }
    }
    return text;
  }

  std::string OneOf(const toml::node& node, std::string_view key,
                    std::initializer_list<std::string_view> allowed) const {
    const std::string text = String(node, key);
    std::string list;
    for (const std::string_view a : allowed) {
      if (a == text) return text;
      list += (list.empty() ? "" : ", ") + std::string(a);
    }
    Fail(node, std::string(key) + " = \"" + text + "\": must be one of " + list);
  }
};

void ReadCriteria(const CampaignReader& r, const toml::table& table, CampaignCriteria& c) {
  mt::CheckKeys(r.source, table, "criteria",
                {"verdict", "tracking_max_m", "tracking_rms_m", "final_error_m", "settling_time_s",
                 "settling_band_pct", "overshoot_pct", "duty_saturation_pct", "missed_deadlines",
                 "credibility_min", "reference_file", "reference_column", "compare_column",
                 "credibility_max_delay_s"});
  for (const auto& [key_name, node] : table) {
    const std::string_view key = key_name.str();
    if (key == "verdict") c.verdict = r.OneOf(node, key, {"PASS", "FLAGGED", "ABORTED"});
    if (key == "tracking_max_m") c.tracking_max_m = r.Bound(node, key, 0.0, false);
    if (key == "tracking_rms_m") c.tracking_rms_m = r.Bound(node, key, 0.0, false);
    if (key == "final_error_m") c.final_error_m = r.Bound(node, key, 0.0, false);
    if (key == "settling_time_s") c.settling_time_s = r.Bound(node, key, 0.0, false);
    if (key == "settling_band_pct") c.settling_band_pct = r.Bound(node, key, 0.0, true);
    if (key == "overshoot_pct") c.overshoot_pct = r.Bound(node, key, 0.0, false);
    if (key == "duty_saturation_pct") c.duty_saturation_pct = r.Bound(node, key, 0.0, false);
    if (key == "missed_deadlines") {
      const std::optional<std::int64_t> count = node.value<std::int64_t>();
      if (!node.is_integer() || !count || *count < 0) {
        r.Fail(node, "missed_deadlines must be a whole number >= 0");
      }
      c.missed_deadlines = static_cast<std::uint64_t>(*count);
    }
    if (key == "credibility_min") c.credibility_min = r.Bound(node, key, 0.0, false);
    if (key == "reference_file") c.reference_file = r.Path(node, key);
    if (key == "reference_column") c.reference_column = r.String(node, key);
    if (key == "compare_column") c.compare_column = r.String(node, key);
    if (key == "credibility_max_delay_s") c.credibility_max_delay_s = r.Bound(node, key, 0.0, true);
  }
}

void ReadParams(const CampaignReader& r, const toml::node& node, CampaignScenario& s) {
  const toml::table* table = node.as_table();
  if (table == nullptr) r.Fail(node, "params must be a table of \"section.key\" = number");
  for (const auto& [key, value] : *table) {
    s.params[std::string(key.str())] = r.Number(value, "params." + std::string(key.str()));
  }
}

/// Every scenario key but name and criteria, read into `s` (from [defaults] or a scenario).
void ReadScenarioKey(const CampaignReader& r, std::string_view key, const toml::node& node,
                     CampaignScenario& s) {
  if (key == "kind") s.kind = r.OneOf(node, key, {"hil", "run"});
  if (key == "clock") s.clock = r.OneOf(node, key, {"virtual", "realtime"});
  if (key == "mode") s.mode = r.OneOf(node, key, {"closedloop", "openloop"});
  if (key == "controller") s.controller = r.Controller(node);
  if (key == "controller_map") s.controller_map = r.Path(node, key);
  if (key == "gains") s.gains = r.Path(node, key);
  if (key == "plant") s.plant = r.Controller(node);  // fmu:PATH reads like a controller's
  if (key == "plant_map") s.plant_map = r.Path(node, key);
  if (key == "config") s.config = r.Path(node, key);
  if (key == "params") ReadParams(r, node, s);
  if (key == "setpoint") s.setpoint = r.Profile(node, key, BuiltinSetpointNames());
  if (key == "input") s.input = r.Profile(node, key, BuiltinProfileNames());
  if (key == "twin_rate_hz") s.twin_rate_hz = r.Number(node, key);
  if (key == "ecs_rate_hz") s.ecs_rate_hz = r.Number(node, key);
  if (key == "duration_s") s.duration_s = r.Bound(node, key, 0.0, false);
  // The flag strings are parsed here, by the parsers the commands use, so a mistake is
  // refused at its own place before any scenario runs, not as a scenario's exit 2.
  if (key == "link_faults") s.link_faults = r.Flags(node, key, CheckLinkFault);
  if (key == "twin_overruns") s.twin_overruns = r.Flags(node, key, CheckOverrun);
  if (key == "ecs_overruns") s.ecs_overruns = r.Flags(node, key, CheckOverrun);
  if (key == "twin_qos") s.twin_qos = r.Flags(node, key, CheckQosRule);
  if (key == "ecs_qos") s.ecs_qos = r.Flags(node, key, CheckQosRule);
  if (key == "twin_max_miss_pct") s.twin_max_miss_pct = r.Bound(node, key, 0.0, false);
  if (key == "ecs_max_miss_pct") s.ecs_max_miss_pct = r.Bound(node, key, 0.0, false);
}

void ReadScenarioTable(const CampaignReader& r, const toml::table& table,
                       std::string_view table_name, bool named, CampaignScenario& s) {
  // A scenario's name is its own; every other key may come from [defaults].
  toml::table keys = table;
  if (named) keys.erase("name");
  mt::CheckKeys(r.source, keys, table_name,
                {"kind",
                 "clock",
                 "mode",
                 "controller",
                 "controller_map",
                 "gains",
                 "plant",
                 "plant_map",
                 "config",
                 "params",
                 "setpoint",
                 "input",
                 "twin_rate_hz",
                 "ecs_rate_hz",
                 "duration_s",
                 "link_faults",
                 "twin_overruns",
                 "ecs_overruns",
                 "twin_qos",
                 "ecs_qos",
                 "twin_max_miss_pct",
                 "ecs_max_miss_pct",
                 "criteria"});
  for (const auto& [key_name, node] : table) {
    const std::string_view key = key_name.str();
    if (key == "name") s.name = r.String(node, key);
    if (key == "criteria") {
      const toml::table* criteria = node.as_table();
      if (criteria == nullptr) r.Fail(node, "criteria must be a table");
      ReadCriteria(r, *criteria, s.criteria);
    }
    ReadScenarioKey(r, key, node, s);
  }
}

void CheckName(const CampaignReader& r, const toml::table& table, const CampaignScenario& s,
               std::set<std::string>& names) {
  const toml::node* name = table.get("name");
  if (name == nullptr) r.Fail(table, "a [[scenario]] needs a name");
  const bool clean = !s.name.empty() && std::all_of(s.name.begin(), s.name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.';
  });
  if (!clean) {
    r.Fail(*name, "scenario name \"" + s.name +
                      "\": use letters, digits, '_', '-' and '.' only (it names files)");
  }
  if (!names.insert(s.name).second) r.Fail(*name, "scenario name \"" + s.name + "\" is used twice");
}

CampaignScenario Defaults(const CampaignReader& r, const toml::table& root) {
  CampaignScenario defaults;
  if (const toml::node* node = root.get("defaults")) {
    const toml::table* table = node->as_table();
    if (table == nullptr) r.Fail(*node, "[defaults] must be a table");
    ReadScenarioTable(r, *table, "[defaults]", false, defaults);
  }
  return defaults;
}

void ReadCampaignTable(const CampaignReader& r, const toml::table& root, Campaign& campaign) {
  const toml::node* node = root.get("campaign");
  if (node == nullptr) return;
  const toml::table* table = node->as_table();
  if (table == nullptr) r.Fail(*node, "[campaign] must be a table");
  mt::CheckKeys(r.source, *table, "[campaign]", {"name", "description"});
  if (const toml::node* name = table->get("name")) campaign.name = r.String(*name, "name");
  if (const toml::node* text = table->get("description")) {
    campaign.description = r.String(*text, "description");
  }
}

}  // namespace campaign_file_reading

Campaign ParseCampaign(const std::string& text, const std::string& source,
                       const std::string& folder) {
  using namespace campaign_file_reading;  // this file's helpers
  const CampaignReader r{source, folder};
  toml::table root;
  try {
    root = mt::ParseRoot(text, source);
    mt::CheckKeys(source, root, "the campaign file", {"campaign", "defaults", "scenario"});
  } catch (const mt::MapTomlError& e) {
    throw CampaignFileError(e.what());
  }
  Campaign campaign;
  campaign.file = source;
  campaign.name = fs::path(source).stem().string();
  std::set<std::string> names;
  try {
    ReadCampaignTable(r, root, campaign);
    const CampaignScenario defaults = Defaults(r, root);
    const toml::array* scenarios = mt::ArrayOfTables(source, root, "scenario");
    if (scenarios == nullptr || scenarios->empty()) {
      throw CampaignFileError(source + ": no [[scenario]]: a campaign runs at least one");
    }
    for (const toml::node& node : *scenarios) {
      const toml::table& table = *node.as_table();
      CampaignScenario s = defaults;
      s.index = campaign.scenarios.size();
      s.where = mt::Where(source, table.source());
      ReadScenarioTable(r, table, "[[scenario]]", true, s);
      CheckName(r, table, s, names);
      CheckScenario(s);  // what the keys mean together, and the flag strings
      campaign.scenarios.push_back(std::move(s));
    }
  } catch (const mt::MapTomlError& e) {
    throw CampaignFileError(e.what());
  }
  return campaign;
}

Campaign LoadCampaign(const std::string& path) {
  using namespace campaign_file_reading;  // this file's helpers
  std::string text;
  try {
    text = mt::ReadMapFile(path, "campaign file",
                           "give the path of a campaign TOML file (docs/testing-campaigns.md)");
  } catch (const mt::MapTomlError& e) {
    throw CampaignFileError(e.what());
  }
  const std::string folder = fs::absolute(path).parent_path().string();
  Campaign campaign = ParseCampaign(text, path, folder);
  return campaign;
}

}  // namespace hiltwin::app
