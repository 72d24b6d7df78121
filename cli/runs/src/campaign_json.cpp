// The JSON result of `hiltwin test` and its reading back (campaign_report.h). A double is
// written as a JSON number, which nlohmann prints with enough digits to read back as the same
// double; a value JSON has no number for (a settling time that never settled is +infinity) is
// written as the string "inf", "-inf" or "nan", so that it too reads back as itself and is not
// confused with null (nothing measured).

#include <cmath>
#include <limits>

#include "hiltwin/runs/campaign_report.h"

namespace hiltwin::app {
namespace campaign_json {

using Json = nlohmann::ordered_json;
constexpr const char* kFormat = "hiltwin-campaign-result/1";

Json Number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

Json Number(const std::optional<double>& value) { return value ? Number(*value) : Json(nullptr); }

Json Numbers(const std::vector<double>& values) {
  Json array = Json::array();
  for (const double value : values) array.push_back(Number(value));
  return array;
}

Json CriterionJson(const CriterionResult& criterion) {
  Json json;
  json["name"] = criterion.name;
  json["unit"] = criterion.unit;
  json["relation"] = criterion.relation;
  json["required"] = Number(criterion.required);
  json["measured"] = Number(criterion.measured);
  json["required_text"] = criterion.required_text;
  json["measured_text"] = criterion.measured_text;
  json["passed"] = criterion.passed;
  return json;
}

Json PlotJson(const ScenarioPlot& plot) {
  Json series = Json::array();
  for (const PlotSeries& one : plot.series) {
    series.push_back(Json{{"name", one.name}, {"values", Numbers(one.values)}});
  }
  return Json{{"y_unit", plot.y_unit}, {"time_s", Numbers(plot.time_s)}, {"series", series}};
}

Json ScenarioJson(const ScenarioResult& scenario) {
  Json json;
  json["index"] = scenario.index;
  json["name"] = scenario.name;
  json["kind"] = scenario.kind;
  json["clock"] = scenario.clock;
  json["controller"] = scenario.controller;
  json["exit_code"] = scenario.exit_code;
  json["verdict"] = scenario.verdict;
  json["error"] = scenario.error;
  json["passed"] = scenario.passed();
  json["criteria"] = Json::array();
  for (const CriterionResult& criterion : scenario.criteria) {
    json["criteria"].push_back(CriterionJson(criterion));
  }
  json["plot"] = PlotJson(scenario.plot);
  json["wall_s"] = Number(scenario.wall_s);
  return json;
}

const char* TypeName(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::boolean:
      return "a boolean";
    case nlohmann::json::value_t::string:
      return "a string";
    case nlohmann::json::value_t::array:
      return "an array";
    case nlohmann::json::value_t::object:
      return "an object";
    default:
      return "a number";
  }
}

/// One object of the JSON being read, with where it is ("scenarios[3].criteria[0]"): every
/// read names the source and the key when the value is missing or of the wrong type.
class Reader {
 public:
  Reader(const nlohmann::json& object, std::string_view source, std::string path)
      : object_(&object), source_(source), path_(std::move(path)) {}

  [[noreturn]] void Refuse(std::string_view key, const std::string& what) const {
    throw CampaignResultError(std::string(source_) + ": key '" + Path(key) + "'" + what);
  }

  std::string String(std::string_view key) const {
    return Field(key, "a string", [](const auto& v) { return v.is_string(); }).get<std::string>();
  }
  bool Bool(std::string_view key) const {
    return Field(key, "true or false", [](const auto& v) { return v.is_boolean(); }).get<bool>();
  }
  int Int(std::string_view key) const {
    const nlohmann::json& value =
        Field(key, "a whole number", [](const auto& v) { return v.is_number_integer(); });
    const auto number = value.get<std::int64_t>();
    if (number < std::numeric_limits<int>::min() || number > std::numeric_limits<int>::max()) {
      Refuse(key, ": " + value.dump() + " is out of range");
    }
    return static_cast<int>(number);
  }
  std::size_t Count(std::string_view key) const {
    return Field(key, "a whole number >= 0",
                 [](const auto& v) {
                   return v.is_number_unsigned() || (v.is_number_integer() && v >= 0);
                 })
        .get<std::size_t>();
  }
  double Double(std::string_view key) const {
    const nlohmann::json& value = Field(key, "a number", &IsNumberLike);
    return ToDouble(value);
  }
  std::optional<double> OptionalDouble(std::string_view key) const {
    const nlohmann::json& value = Field(key, "a number or null", &IsNumberOrNull);
    if (value.is_null()) return std::nullopt;
    return ToDouble(value);
  }
  std::vector<double> Doubles(std::string_view key) const {
    const nlohmann::json& array =
        Field(key, "an array of numbers", [](const auto& v) { return v.is_array(); });
    std::vector<double> values;
    values.reserve(array.size());
    for (std::size_t i = 0; i < array.size(); ++i) {
      if (!IsNumberLike(array[i])) {
        Refuse(Indexed(key, i), Expected("a number", array[i]));
      }
      values.push_back(ToDouble(array[i]));
    }
    return values;
  }
  Reader Object(std::string_view key) const {
    return {Field(key, "an object", [](const auto& v) { return v.is_object(); }), source_,
            Path(key)};
  }
  std::vector<Reader> Objects(std::string_view key) const {
    const nlohmann::json& array =
        Field(key, "an array of objects", [](const auto& v) { return v.is_array(); });
    std::vector<Reader> objects;
    for (std::size_t i = 0; i < array.size(); ++i) {
      if (!array[i].is_object()) Refuse(Indexed(key, i), Expected("an object", array[i]));
      objects.emplace_back(array[i], source_, Path(Indexed(key, i)));
    }
    return objects;
  }

 private:
  static bool IsNumberLike(const nlohmann::json& value) {
    if (value.is_number()) return true;
    if (!value.is_string()) return false;
    const auto& text = value.get_ref<const std::string&>();
    return text == "inf" || text == "-inf" || text == "nan";
  }
  static bool IsNumberOrNull(const nlohmann::json& value) {
    return value.is_null() || IsNumberLike(value);
  }
  static double ToDouble(const nlohmann::json& value) {
    if (value.is_number()) return value.get<double>();
    const auto& text = value.get_ref<const std::string&>();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
    const double infinity = std::numeric_limits<double>::infinity();
    return text == "inf" ? infinity : -infinity;
  }
  static std::string Indexed(std::string_view key, std::size_t i) {
    return std::string(key) + "[" + std::to_string(i) + "]";
  }
  static std::string Expected(const char* expected, const nlohmann::json& found) {
    return std::string(": expected ") + expected + ", found " + TypeName(found);
  }
  std::string Path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }
  template <class TypeIs>
  const nlohmann::json& Field(std::string_view key, const char* expected, TypeIs type_is) const {
    const auto found = object_->find(key);
    if (found == object_->end()) Refuse(key, std::string(" is missing: expected ") + expected);
    if (!type_is(*found)) Refuse(key, Expected(expected, *found));
    return *found;
  }

  const nlohmann::json* object_;
  std::string_view source_;
  std::string path_;
};

CriterionResult ReadCriterion(const Reader& in) {
  CriterionResult criterion;
  criterion.name = in.String("name");
  criterion.unit = in.String("unit");
  criterion.relation = in.String("relation");
  criterion.required = in.OptionalDouble("required");
  criterion.measured = in.OptionalDouble("measured");
  criterion.required_text = in.String("required_text");
  criterion.measured_text = in.String("measured_text");
  criterion.passed = in.Bool("passed");
  return criterion;
}

ScenarioPlot ReadPlot(const Reader& in) {
  ScenarioPlot plot;
  plot.y_unit = in.String("y_unit");
  plot.time_s = in.Doubles("time_s");
  for (const Reader& series : in.Objects("series")) {
    plot.series.push_back(PlotSeries{series.String("name"), series.Doubles("values")});
  }
  return plot;
}

ScenarioResult ReadScenario(const Reader& in, std::size_t scenarios_in_file) {
  ScenarioResult scenario;
  scenario.index = in.Count("index");
  if (scenario.index >= scenarios_in_file) {
    in.Refuse("index", ": " + std::to_string(scenario.index) + " is not below the file's " +
                           std::to_string(scenarios_in_file) + " scenarios (scenarios_in_file)");
  }
  scenario.name = in.String("name");
  scenario.kind = in.String("kind");
  scenario.clock = in.String("clock");
  scenario.controller = in.String("controller");
  scenario.exit_code = in.Int("exit_code");
  scenario.verdict = in.String("verdict");
  scenario.error = in.String("error");
  for (const Reader& criterion : in.Objects("criteria")) {
    scenario.criteria.push_back(ReadCriterion(criterion));
  }
  scenario.plot = ReadPlot(in.Object("plot"));
  scenario.wall_s = in.Double("wall_s");
  // "passed" is derived from the criteria and the error; one that disagrees was edited.
  if (in.Bool("passed") != scenario.passed()) {
    in.Refuse("passed", ": disagrees with the scenario's criteria and error (was it edited?)");
  }
  return scenario;
}

ShardSpec ReadShard(const Reader& in) {
  ShardSpec shard{in.Count("index"), in.Count("count")};
  if (shard.index < 1 || shard.index > shard.count) {
    in.Refuse("index", ": shard " + std::to_string(shard.index) + "/" +
                           std::to_string(shard.count) + " does not exist (K of K/N is 1 to N)");
  }
  return shard;
}

// The counts and the exit code are derived from the scenarios; ones that disagree were edited.
void CheckDerived(const Reader& in, const CampaignResult& result) {
  const std::size_t failed = result.failed();
  if (in.Count("passed") != result.scenarios.size() - failed) {
    in.Refuse("passed", ": disagrees with the scenarios' results (was it edited?)");
  }
  if (in.Count("failed") != failed) {
    in.Refuse("failed", ": disagrees with the scenarios' results (was it edited?)");
  }
  if (in.Int("exit_code") != result.exit_code()) {
    in.Refuse("exit_code", ": disagrees with the scenarios' results (was it edited?)");
  }
}

void CheckFormat(const nlohmann::json& json, std::string_view source) {
  const std::string not_ours = std::string(source) +
                               ": not a result of `hiltwin test --json` (expected a JSON object "
                               "with \"format\": \"" +
                               kFormat + "\")";
  if (!json.is_object()) throw CampaignResultError(not_ours);
  const auto format = json.find("format");
  if (format == json.end() || !format->is_string()) throw CampaignResultError(not_ours);
  if (format->get<std::string>() != kFormat) {
    throw CampaignResultError(std::string(source) + ": key 'format': \"" +
                              format->get<std::string>() + "\" is not \"" + kFormat +
                              "\" (written by another hiltwin version? read it with that one)");
  }
}

}  // namespace campaign_json

nlohmann::ordered_json ToJson(const CampaignResult& result) {
  using campaign_json::Json;
  Json json;
  json["format"] = campaign_json::kFormat;
  json["campaign"] = result.name;
  json["file"] = result.file;
  json["scenarios_in_file"] = result.scenarios_in_file;
  json["filter"] = result.filter;
  json["shards"] = Json::array();
  for (const ShardSpec& shard : result.shards) {
    json["shards"].push_back(Json{{"index", shard.index}, {"count", shard.count}});
  }
  const std::size_t failed = result.failed();
  json["passed"] = result.scenarios.size() - failed;
  json["failed"] = failed;
  json["exit_code"] = result.exit_code();
  json["scenarios"] = Json::array();
  for (const ScenarioResult& scenario : result.scenarios) {
    json["scenarios"].push_back(campaign_json::ScenarioJson(scenario));
  }
  json["wall_s"] = campaign_json::Number(result.wall_s);
  return json;
}

CampaignResult CampaignResultFromJson(const nlohmann::json& json, std::string_view source) {
  campaign_json::CheckFormat(json, source);
  const campaign_json::Reader in(json, source, "");
  CampaignResult result;
  result.name = in.String("campaign");
  result.file = in.String("file");
  result.scenarios_in_file = in.Count("scenarios_in_file");
  result.filter = in.String("filter");
  for (const campaign_json::Reader& shard : in.Objects("shards")) {
    result.shards.push_back(campaign_json::ReadShard(shard));
  }
  for (const campaign_json::Reader& scenario : in.Objects("scenarios")) {
    result.scenarios.push_back(campaign_json::ReadScenario(scenario, result.scenarios_in_file));
  }
  result.wall_s = in.Double("wall_s");
  campaign_json::CheckDerived(in, result);
  return result;
}

}  // namespace hiltwin::app
