// `hiltwin test`'s outputs (campaign_report.h): the JSON result read back as itself and its
// refusals, shard results merged into the unsharded run's result, JUnit XML valid against the
// schema Jenkins reads (junit.xsd, checked with libxml2), the HTML page and the text lines.

#include "hiltwin/runs/campaign_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <libxml/parser.h>
#include <libxml/xmlschemas.h>
#include <libxml/xpath.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fakes/test_paths.h"

namespace hiltwin::app {
// A named namespace: the campaign tests compile as one unity unit.
namespace campaign_report_test {

using ::testing::HasSubstr;

CriterionResult NumberCriterion(std::string name, std::string unit, std::string relation,
                                double required, std::optional<double> measured, bool passed) {
  CriterionResult criterion;
  criterion.name = std::move(name);
  criterion.unit = std::move(unit);
  criterion.relation = std::move(relation);
  criterion.required = required;
  criterion.measured = measured;
  criterion.passed = passed;
  return criterion;
}

CriterionResult VerdictCriterion(std::string required, std::string measured, bool passed) {
  CriterionResult criterion;
  criterion.name = "verdict";
  criterion.relation = "at most";
  criterion.required_text = std::move(required);
  criterion.measured_text = std::move(measured);
  criterion.passed = passed;
  return criterion;
}

ScenarioResult Scenario(std::size_t index, std::string name, double wall_s) {
  ScenarioResult scenario;
  scenario.index = index;
  scenario.name = std::move(name);
  scenario.kind = "hil";
  scenario.clock = "virtual";
  scenario.controller = "pid";
  scenario.verdict = "PASS";
  scenario.wall_s = wall_s;
  return scenario;
}

ScenarioPlot Plot(std::vector<std::string> names) {
  ScenarioPlot plot;
  plot.y_unit = "m";
  for (int i = 0; i < 5; ++i) plot.time_s.push_back(0.001 * i);
  double offset = 0.0;
  for (std::string& name : names) {
    // 0.1 + 0.2 and 1/3: doubles that need all 17 digits to read back as themselves.
    plot.series.push_back(PlotSeries{std::move(name), {0.0, 0.1 + 0.2, 1.0 / 3.0, 0.5, offset}});
    offset += 0.25;
  }
  return plot;
}

// Seven scenarios of an eight-scenario file: passes, failures (a number criterion, the
// verdict, a figure never measured, a settling time of +infinity), an error, no criteria,
// plots, and names the outputs must escape.
CampaignResult SampleCampaign() {
  CampaignResult result;
  result.name = "smoke & <friends>";
  result.file = "campaigns/smoke.toml";
  result.scenarios_in_file = 8;
  result.shards = {ShardSpec{1, 1}};
  result.wall_s = 12.5;

  ScenarioResult step = Scenario(0, "step_response", 0.41);
  step.criteria = {NumberCriterion("tracking_max_m", "m", "<=", 0.003, 0.0012, true)};
  step.plot = Plot({"setpoint_left_m", "wheel_left_m"});

  ScenarioResult burst = Scenario(1, "burst & <lost> \"frames\" 'x'", 0.39);
  burst.verdict = "FLAGGED";
  burst.criteria = {VerdictCriterion("PASS", "FLAGGED", false),
                    NumberCriterion("tracking_max_m", "m", "<=", 0.003, 0.0041, false)};
  burst.plot = Plot({"setpoint_left_m", "wheel_left_m"});

  ScenarioResult no_report = Scenario(2, "no_report", 0.05);
  no_report.exit_code = 4;
  no_report.verdict = "";
  no_report.error = "hil exited with 4 and wrote no report";
  no_report.criteria = {VerdictCriterion("PASS", "", false),
                        NumberCriterion("tracking_max_m", "m", "<=", 0.003, std::nullopt, false)};

  ScenarioResult open_loop = Scenario(3, "open_loop", 1.25);
  open_loop.kind = "run";
  open_loop.controller = "";
  open_loop.verdict = "";
  open_loop.plot = Plot({"wheel_left_m", "wheel_right_m"});

  ScenarioResult settle = Scenario(5, "never_settles", 2.0);
  settle.criteria = {NumberCriterion("settling_time_s", "s", "<=", 0.5,
                                     std::numeric_limits<double>::infinity(), false),
                     NumberCriterion("overshoot_pct", "%", "<=", 10.0, 0.1 + 0.2, true)};

  ScenarioResult deadlines = Scenario(6, "deadlines", 0.3);
  deadlines.criteria = {NumberCriterion("missed_deadlines", "1", "<=", 0.0, 0.0, true),
                        NumberCriterion("credibility_min", "1", ">=", 0.9, 0.95, true)};

  ScenarioResult lib = Scenario(7, "library_controller", 0.7);
  lib.controller = "lib:/abs/x.so";
  lib.criteria = {VerdictCriterion("FLAGGED", "PASS", true)};

  result.scenarios = {step, burst, no_report, open_loop, settle, deadlines, lib};
  return result;
}

// ---- JSON ------------------------------------------------------------------------------------

std::string RefusalOf(const nlohmann::json& json) {
  try {
    (void)CampaignResultFromJson(json, "r.json");
  } catch (const CampaignResultError& e) {
    return e.what();
  }
  return "(accepted)";
}

nlohmann::json SampleJson() { return ToJson(SampleCampaign()); }

TEST(CampaignJson, ReadsBackAsItselfThroughText) {
  const CampaignResult sample = SampleCampaign();
  const nlohmann::ordered_json json = ToJson(sample);
  const std::string text = json.dump(2);
  const CampaignResult back = CampaignResultFromJson(nlohmann::json::parse(text), "r.json");
  EXPECT_EQ(ToJson(back), json);
  EXPECT_EQ(ToJson(back).dump(2), text);

  // The values themselves, not only their JSON: exact doubles, nullopt, +infinity, texts.
  ASSERT_EQ(back.scenarios.size(), 7U);
  EXPECT_EQ(back.scenarios[0].plot.series[1].values[1], 0.1 + 0.2);
  EXPECT_EQ(back.scenarios[0].plot.series[1].values[2], 1.0 / 3.0);
  EXPECT_EQ(back.scenarios[0].plot.time_s[3], sample.scenarios[0].plot.time_s[3]);
  EXPECT_EQ(back.scenarios[2].criteria[1].measured, std::nullopt);
  EXPECT_EQ(back.scenarios[2].error, "hil exited with 4 and wrote no report");
  EXPECT_EQ(back.scenarios[2].criteria[0].measured_text, "");
  EXPECT_EQ(back.scenarios[1].criteria[0].measured_text, "FLAGGED");
  EXPECT_EQ(back.scenarios[1].criteria[0].required, std::nullopt);
  ASSERT_TRUE(back.scenarios[4].criteria[0].measured.has_value());
  EXPECT_TRUE(std::isinf(*back.scenarios[4].criteria[0].measured));
  EXPECT_EQ(back.scenarios[4].criteria[1].measured, 0.1 + 0.2);
  EXPECT_EQ(back.scenarios[4].index, 5U);
  EXPECT_EQ(back.scenarios[6].controller, "lib:/abs/x.so");
  EXPECT_EQ(back.wall_s, 12.5);
  EXPECT_EQ(back.exit_code(), 3);
  EXPECT_EQ(back.failed(), 3U);
  EXPECT_THAT(text, HasSubstr("\"measured\": null"));
  EXPECT_THAT(text, HasSubstr("\"measured\": \"inf\""));
}

TEST(CampaignJson, KeysInTheDocumentedOrderWithDerivedCounts) {
  const nlohmann::ordered_json json = ToJson(SampleCampaign());
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"format", "campaign", "file", "scenarios_in_file",
                                            "filter", "shards", "passed", "failed", "exit_code",
                                            "scenarios", "wall_s"}));
  EXPECT_EQ(json["format"], "hiltwin-campaign-result/1");
  EXPECT_EQ(json["passed"], 4);
  EXPECT_EQ(json["failed"], 3);
  EXPECT_EQ(json["exit_code"], 3);
  EXPECT_EQ(json["scenarios"][1]["passed"], false);
  EXPECT_EQ(json["scenarios"][3]["passed"], true);
  EXPECT_EQ(json["shards"], nlohmann::ordered_json::parse(R"([{"index":1,"count":1}])"));
}

TEST(CampaignJson, AnEmptyCampaignPassesAndReadsBack) {
  CampaignResult empty;
  empty.name = "none";
  empty.shards = {ShardSpec{1, 1}};
  EXPECT_EQ(empty.exit_code(), 0);
  const nlohmann::ordered_json json = ToJson(empty);
  EXPECT_EQ(ToJson(CampaignResultFromJson(json, "r.json")), json);
}

TEST(CampaignJson, RefusesWhatIsNotItsFormat) {
  const std::string not_ours =
      "r.json: not a result of `hiltwin test --json` (expected a JSON object with \"format\": "
      "\"hiltwin-campaign-result/1\")";
  EXPECT_EQ(RefusalOf(nlohmann::json::array()), not_ours);
  nlohmann::json json = SampleJson();
  json.erase("format");
  EXPECT_EQ(RefusalOf(json), not_ours);
  json["format"] = "hiltwin-campaign-result/2";
  EXPECT_EQ(RefusalOf(json),
            "r.json: key 'format': \"hiltwin-campaign-result/2\" is not "
            "\"hiltwin-campaign-result/1\" (written by another hiltwin version? read it with "
            "that one)");
}

struct Refusal {
  std::function<void(nlohmann::json&)> edit;
  std::string message;
};

TEST(CampaignJson, RefusesAMissingOrMistypedKeyNamingIt) {
  const std::vector<Refusal> refusals = {
      {[](nlohmann::json& j) {
         j["scenarios"][3]["criteria"] = nlohmann::json::parse(R"([{"name": "x"}])");
       },
       "r.json: key 'scenarios[3].criteria[0].unit' is missing: expected a string"},
      {[](nlohmann::json& j) { j["scenarios"][1]["criteria"][1]["measured"] = "0.004"; },
       "r.json: key 'scenarios[1].criteria[1].measured': expected a number or null, found a "
       "string"},
      {[](nlohmann::json& j) { j["scenarios"][0]["plot"].erase("time_s"); },
       "r.json: key 'scenarios[0].plot.time_s' is missing: expected an array of numbers"},
      {[](nlohmann::json& j) { j["scenarios"][0]["plot"]["series"][1]["values"][2] = true; },
       "r.json: key 'scenarios[0].plot.series[1].values[2]': expected a number, found a boolean"},
      {[](nlohmann::json& j) { j["scenarios_in_file"] = -1; },
       "r.json: key 'scenarios_in_file': expected a whole number >= 0, found a number"},
      {[](nlohmann::json& j) { j["scenarios"][2]["exit_code"] = 4.5; },
       "r.json: key 'scenarios[2].exit_code': expected a whole number, found a number"},
      {[](nlohmann::json& j) { j["scenarios"] = nlohmann::json::object(); },
       "r.json: key 'scenarios': expected an array of objects, found an object"},
      {[](nlohmann::json& j) { j["scenarios"][0] = 3; },
       "r.json: key 'scenarios[0]': expected an object, found a number"},
      {[](nlohmann::json& j) { j["wall_s"] = nullptr; },
       "r.json: key 'wall_s': expected a number, found null"},
      {[](nlohmann::json& j) { j["shards"][0]["index"] = 2; },
       "r.json: key 'shards[0].index': shard 2/1 does not exist (K of K/N is 1 to N)"},
      {[](nlohmann::json& j) { j["scenarios"][6]["index"] = 8; },
       "r.json: key 'scenarios[6].index': 8 is not below the file's 8 scenarios "
       "(scenarios_in_file)"},
      {[](nlohmann::json& j) { j["failed"] = 0; },
       "r.json: key 'failed': disagrees with the scenarios' results (was it edited?)"},
      {[](nlohmann::json& j) { j["scenarios"][1]["passed"] = true; },
       "r.json: key 'scenarios[1].passed': disagrees with the scenario's criteria and error (was "
       "it edited?)"},
  };
  for (const Refusal& refusal : refusals) {
    nlohmann::json json = SampleJson();
    refusal.edit(json);
    EXPECT_EQ(RefusalOf(json), refusal.message);
  }
}

// ---- Merge -----------------------------------------------------------------------------------

// Shard K of N as `hiltwin test --shard K/N` would give it, with its own wall-clock times.
std::vector<CampaignResult> Shards(const CampaignResult& whole, std::size_t count) {
  std::vector<CampaignResult> shards;
  for (std::size_t k = 1; k <= count; ++k) {
    CampaignResult shard = whole;
    shard.shards = {ShardSpec{k, count}};
    shard.scenarios.clear();
    for (ScenarioResult scenario : whole.scenarios) {
      if (scenario.index % count != k - 1) continue;
      scenario.wall_s += 100.0;
      shard.scenarios.push_back(scenario);
    }
    shard.wall_s = 10.0 + static_cast<double>(k);
    shards.push_back(shard);
  }
  return shards;
}

// What two runs of one lockstep campaign share: all but the shard list and wall-clock times.
nlohmann::ordered_json WithoutWallClock(nlohmann::ordered_json json) {
  json.erase("shards");
  json.erase("wall_s");
  for (auto& scenario : json["scenarios"]) scenario.erase("wall_s");
  return json;
}

std::string MergeRefusal(std::vector<CampaignResult> shards) {
  try {
    (void)MergeCampaignResults(std::move(shards));
  } catch (const CampaignResultError& e) {
    return e.what();
  }
  return "(merged)";
}

TEST(CampaignMerge, ThreeShardsGiveTheUnshardedResult) {
  const CampaignResult whole = SampleCampaign();
  std::vector<CampaignResult> shards = Shards(whole, 3);
  ASSERT_EQ(shards[0].scenarios.size(), 3U);  // indices 0, 3, 6
  // Given out of order, and each read back from its JSON text as `hiltwin test merge` does.
  std::vector<CampaignResult> read_back;
  for (const std::size_t k : {2U, 0U, 1U}) {
    read_back.push_back(
        CampaignResultFromJson(nlohmann::json::parse(ToJson(shards[k]).dump()), "shard.json"));
  }
  const CampaignResult merged = MergeCampaignResults(std::move(read_back));

  EXPECT_EQ(WithoutWallClock(ToJson(merged)), WithoutWallClock(ToJson(whole)));
  ASSERT_EQ(merged.shards.size(), 3U);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(merged.shards[k].index, k + 1);
    EXPECT_EQ(merged.shards[k].count, 3U);
  }
  EXPECT_EQ(merged.wall_s, 13.0);
  EXPECT_EQ(merged.exit_code(), 3);
  ASSERT_EQ(merged.scenarios.size(), whole.scenarios.size());
  EXPECT_EQ(merged.scenarios[4].name, "never_settles");
}

TEST(CampaignMerge, OneShardMergesToItself) {
  const CampaignResult whole = SampleCampaign();
  EXPECT_EQ(ToJson(MergeCampaignResults({whole})), ToJson(whole));
}

TEST(CampaignMerge, RefusesShardsThatDoNotJoin) {
  const CampaignResult whole = SampleCampaign();
  EXPECT_EQ(MergeRefusal({}),
            "nothing to merge: give the JSON results of a campaign's shards (hiltwin test "
            "--shard K/N --json FILE)");

  std::vector<CampaignResult> other_file = Shards(whole, 2);
  other_file[1].file = "campaigns/other.toml";
  EXPECT_EQ(MergeRefusal(other_file),
            "cannot merge: result 2 (shard 2/2) and result 1 (shard 1/2) differ in campaign "
            "file: 'campaigns/other.toml' against 'campaigns/smoke.toml': merge the shards of one "
            "run of one campaign file");

  std::vector<CampaignResult> other_count = Shards(whole, 2);
  other_count[0].scenarios_in_file = 9;
  EXPECT_THAT(MergeRefusal(other_count), HasSubstr("differ in scenarios in the file: 8 against 9"));

  std::vector<CampaignResult> other_filter = Shards(whole, 2);
  other_filter[1].filter = "step*";
  EXPECT_THAT(MergeRefusal(other_filter), HasSubstr("differ in --filter: 'step*' against ''"));

  std::vector<CampaignResult> twice = Shards(whole, 3);
  twice.push_back(twice[1]);
  EXPECT_EQ(MergeRefusal(twice),
            "cannot merge: shard 2/3 is given twice: give each shard's result once");

  std::vector<CampaignResult> same_scenario = Shards(whole, 2);
  same_scenario[1].scenarios.push_back(whole.scenarios[0]);
  EXPECT_EQ(MergeRefusal(same_scenario),
            "cannot merge: scenario 0 ('step_response') is in two of the results: give each "
            "shard's result once");

  std::vector<CampaignResult> split_differently = {Shards(whole, 3)[0], Shards(whole, 2)[1]};
  EXPECT_EQ(MergeRefusal(split_differently),
            "cannot merge: shard 1/3 beside shard 2/2: the results come from runs split "
            "differently (--shard K/N)");
}

// ---- JUnit -----------------------------------------------------------------------------------

#if LIBXML_VERSION >= 21200
using XmlErrorArg = const xmlError*;
#else
using XmlErrorArg = xmlErrorPtr;
#endif

void CollectXmlError(void* messages, XmlErrorArg error) {
  if (error != nullptr && error->message != nullptr) {
    *static_cast<std::string*>(messages) += error->message;
  }
}

using XmlDoc = std::unique_ptr<xmlDoc, decltype(&xmlFreeDoc)>;

XmlDoc ParseXml(const std::string& xml, std::string& messages) {
  xmlSetStructuredErrorFunc(&messages, &CollectXmlError);
  XmlDoc doc(xmlReadMemory(xml.data(), static_cast<int>(xml.size()), "junit.xml", nullptr,
                           XML_PARSE_NONET),
             &xmlFreeDoc);
  xmlSetStructuredErrorFunc(nullptr, nullptr);
  return doc;
}

// "" when `xml` is well-formed and valid against junit.xsd, else what libxml2 said.
std::string JunitSchemaErrors(const std::string& xml) {
  std::string messages;
  XmlDoc doc = ParseXml(xml, messages);
  if (!doc) return "not well-formed: " + messages;
  std::unique_ptr<xmlSchemaParserCtxt, decltype(&xmlSchemaFreeParserCtxt)> parser(
      xmlSchemaNewParserCtxt(HILTWIN_JUNIT_XSD), &xmlSchemaFreeParserCtxt);
  std::unique_ptr<xmlSchema, decltype(&xmlSchemaFree)> schema(xmlSchemaParse(parser.get()),
                                                              &xmlSchemaFree);
  if (!schema) return std::string("cannot read the schema ") + HILTWIN_JUNIT_XSD;
  std::unique_ptr<xmlSchemaValidCtxt, decltype(&xmlSchemaFreeValidCtxt)> validator(
      xmlSchemaNewValidCtxt(schema.get()), &xmlSchemaFreeValidCtxt);
  xmlSchemaSetValidStructuredErrors(validator.get(), &CollectXmlError, &messages);
  const int status = xmlSchemaValidateDoc(validator.get(), doc.get());
  if (status != 0) return "invalid (" + std::to_string(status) + "): " + messages;
  return "";
}

// The string value of an XPath expression on `xml`.
std::string XPath(const std::string& xml, const std::string& expression) {
  std::string messages;
  XmlDoc doc = ParseXml(xml, messages);
  if (!doc) return "not well-formed: " + messages;
  std::unique_ptr<xmlXPathContext, decltype(&xmlXPathFreeContext)> context(
      xmlXPathNewContext(doc.get()), &xmlXPathFreeContext);
  std::unique_ptr<xmlXPathObject, decltype(&xmlXPathFreeObject)> value(
      xmlXPathEvalExpression(
          reinterpret_cast<const xmlChar*>(("string(" + expression + ")").c_str()), context.get()),
      &xmlXPathFreeObject);
  if (!value || value->stringval == nullptr) return "(no value)";
  return reinterpret_cast<const char*>(value->stringval);
}

std::string CountOf(const std::string& xml, const std::string& path) {
  return XPath(xml, "count(" + path + ")");
}

TEST(CampaignJunit, ValidatesAgainstTheJenkinsSchema) {
  const std::string xml = ToJunitXml(SampleCampaign());
  EXPECT_EQ(JunitSchemaErrors(xml), "") << xml;
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@name"), "smoke & <friends>");
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@tests"), "7");
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@failures"), "2");
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@errors"), "1");
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@skipped"), "0");
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@time"), "12.500");
  EXPECT_EQ(XPath(xml, "/testsuites/@failures"), "2");
  EXPECT_EQ(CountOf(xml, "//testcase"), "7");
  EXPECT_EQ(CountOf(xml, "//failure"), "3");
  EXPECT_EQ(CountOf(xml, "//error"), "1");
  EXPECT_EQ(XPath(xml, "//property[@name='file']/@value"), "campaigns/smoke.toml");
  EXPECT_EQ(XPath(xml, "//property[@name='shards']/@value"), "1/1");
}

TEST(CampaignJunit, OneFailurePerFailedCriterionAndTheErrorWithItsCriteria) {
  const std::string xml = ToJunitXml(SampleCampaign());
  // The name with & < > " ' reads back from the XML as it was.
  const std::string burst = "//testcase[@name=concat('burst & <lost> \"frames\" ', \"'x'\")]";
  EXPECT_EQ(XPath(xml, burst + "/@classname"), "smoke & <friends>");
  EXPECT_EQ(XPath(xml, burst + "/@time"), "0.390");
  EXPECT_EQ(CountOf(xml, burst + "/failure"), "2");
  EXPECT_EQ(XPath(xml, burst + "/failure[1]/@message"),
            "verdict: measured FLAGGED, required at most PASS");
  EXPECT_EQ(XPath(xml, burst + "/failure[2]/@message"),
            "tracking_max_m: measured 0.0041 m, required <= 0.003 m");
  EXPECT_EQ(XPath(xml, "//testcase[@name='never_settles']/failure/@message"),
            "settling_time_s: measured inf s, required <= 0.5 s");
  EXPECT_EQ(CountOf(xml, "//testcase[@name='step_response']/*[self::failure or self::error]"), "0");

  const std::string no_report = "//testcase[@name='no_report']";
  EXPECT_EQ(CountOf(xml, no_report + "/failure"), "0");
  EXPECT_EQ(XPath(xml, no_report + "/error/@message"), "hil exited with 4 and wrote no report");
  EXPECT_EQ(XPath(xml, no_report + "/error"),
            "hil exited with 4 and wrote no report\n"
            "verdict: measured nothing (the run gave no verdict), required at most PASS\n"
            "tracking_max_m: measured nothing (the run gave no figure), required <= 0.003 m");
  EXPECT_EQ(XPath(xml, no_report + "/system-out"),
            "kind hil, clock virtual, controller pid, exit code 4");
}

TEST(CampaignJunit, ControlCharactersAndBadUtf8StayReadable) {
  CampaignResult result = SampleCampaign();
  result.scenarios[2].name = std::string("bell\x07") + "\xff" + "end";
  // A bad 2-byte sequence, a good euro sign and emoji, an overlong '/' and a surrogate.
  result.scenarios[2].error = std::string("line one\nline\ttwo\x01\x1b[31m") + "\xc3\x28" +
                              " \xe2\x82\xac\xf0\x9f\x99\x82 \xc0\xaf \xed\xa0\x80.";
  const std::string xml = ToJunitXml(result);
  EXPECT_EQ(JunitSchemaErrors(xml), "") << xml;
  EXPECT_EQ(XPath(xml, "//testcase[3]/@name"),
            "bell\xef\xbf\xbd\xef\xbf\xbd"
            "end");
  EXPECT_EQ(XPath(xml, "//testcase[3]/error/@message"),
            "line one line two\xef\xbf\xbd\xef\xbf\xbd[31m\xef\xbf\xbd( "
            "\xe2\x82\xac\xf0\x9f\x99\x82 \xef\xbf\xbd \xef\xbf\xbd.");
  EXPECT_THAT(XPath(xml, "//testcase[3]/error"), HasSubstr("line one\nline\ttwo"));
}

TEST(CampaignJunit, AnEmptyCampaignIsValid) {
  CampaignResult empty;
  empty.name = "none";
  const std::string xml = ToJunitXml(empty);
  EXPECT_EQ(JunitSchemaErrors(xml), "") << xml;
  EXPECT_EQ(XPath(xml, "/testsuites/testsuite/@tests"), "0");
}

// The validator is live: documents the schema forbids fail, so a pass above means something.
TEST(CampaignJunit, TheSchemaRefusesBrokenDocuments) {
  const std::string good = ToJunitXml(SampleCampaign());
  ASSERT_EQ(JunitSchemaErrors(good), "");

  std::string nameless = good;
  const std::string named =
      "<testcase classname=\"smoke &amp; &lt;friends&gt;\" name=\"step_response\"";
  ASSERT_NE(nameless.find(named), std::string::npos);
  nameless.replace(nameless.find(named), named.size(), "<testcase classname=\"x\"");
  EXPECT_THAT(JunitSchemaErrors(nameless), HasSubstr("invalid"));

  std::string no_failures_count = good;
  const std::string failures = " failures=\"2\" errors=\"1\" skipped=\"0\"";
  ASSERT_NE(no_failures_count.find(failures), std::string::npos);
  no_failures_count.replace(no_failures_count.find(failures), failures.size(),
                            " errors=\"1\" skipped=\"0\"");
  EXPECT_THAT(JunitSchemaErrors(no_failures_count), HasSubstr("invalid"));

  std::string exponent_time = good;
  exponent_time.replace(exponent_time.find("time=\"12.500\""), 13, "time=\"1.25e1\"");
  EXPECT_THAT(JunitSchemaErrors(exponent_time), HasSubstr("invalid"));

  EXPECT_THAT(JunitSchemaErrors("<testsuites><testsuite name=\"a & b\"/></testsuites>"),
              HasSubstr("not well-formed"));
}

// ---- HTML ------------------------------------------------------------------------------------

std::size_t Occurrences(const std::string& text, const std::string& part) {
  std::size_t count = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) {
    ++count;
  }
  return count;
}

TEST(CampaignHtml, OnePageWithTheTableAndAPlotPerScenario) {
  const std::string html = ToHtml(SampleCampaign());
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0U);
  EXPECT_THAT(html, HasSubstr("<title>hiltwin test: smoke &amp; &lt;friends&gt;</title>"));
  EXPECT_THAT(html, HasSubstr("4 passed, 3 failed of 7"));
  EXPECT_THAT(html, HasSubstr("<h2>burst &amp; &lt;lost&gt; &quot;frames&quot; 'x' "));
  EXPECT_EQ(html.find("<lost>"), std::string::npos);
  EXPECT_EQ(html.find("<friends>"), std::string::npos);
  for (const char* name : {"step_response", "no_report", "open_loop", "never_settles", "deadlines",
                           "library_controller"}) {
    EXPECT_EQ(Occurrences(html, std::string("<h2>") + name + " "), 1U) << name;
  }

  // Self-contained: no script, no link, no address of anything elsewhere.
  EXPECT_EQ(html.find("http"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);

  // Three scenarios have a plot, each titled with its name and its series in the legend.
  EXPECT_EQ(Occurrences(html, "<svg"), 3U);
  EXPECT_EQ(Occurrences(html, "</svg>"), 3U);
  EXPECT_THAT(html, HasSubstr("class=\"title\">burst &amp; &lt;lost&gt; &quot;frames&quot;"));
  EXPECT_THAT(html, HasSubstr(">wheel_right_m</text>"));
  EXPECT_THAT(html, HasSubstr(">value (m)</text>"));
  EXPECT_EQ(Occurrences(html, "<polyline"), 6U);
  EXPECT_EQ(Occurrences(html, "no plot: the scenario left no log"), 4U);

  // Rows: 10 criteria (5 passed), the error's row (failed), open_loop's "no criteria" row
  // (passed).
  EXPECT_EQ(Occurrences(html, "<td class=\"pass\">PASS</td>"), 6U);
  EXPECT_EQ(Occurrences(html, "<td class=\"fail\">FAIL</td>"), 6U);
  EXPECT_THAT(html, HasSubstr("<td>tracking_max_m</td><td>&lt;= 0.003 m</td><td>0.0041 m</td>"
                              "<td class=\"fail\">FAIL</td>"));
  EXPECT_THAT(html, HasSubstr("<td>nothing (the run gave no figure)</td>"));
  EXPECT_THAT(html, HasSubstr("error: hil exited with 4 and wrote no report"));
  EXPECT_EQ(ToHtml(SampleCampaign()), html);  // nothing in it depends on when it was written
}

// ---- Text ------------------------------------------------------------------------------------

TEST(CampaignText, ScenarioLines) {
  const CampaignResult sample = SampleCampaign();
  EXPECT_EQ(FormatScenarioLine(sample.scenarios[0], 3, 12), "[3/12] PASS step_response 0.41 s");
  ScenarioResult burst = sample.scenarios[1];
  burst.name = "burst_lost_frames";
  burst.criteria.erase(burst.criteria.begin());
  EXPECT_EQ(FormatScenarioLine(burst, 4, 12),
            "[4/12] FAIL burst_lost_frames 0.39 s: tracking_max_m measured 0.0041 m, required <= "
            "0.003 m");
  EXPECT_EQ(FormatScenarioLine(sample.scenarios[1], 4, 12),
            "[4/12] FAIL burst & <lost> \"frames\" 'x' 0.39 s: verdict measured FLAGGED, required "
            "at most PASS; tracking_max_m measured 0.0041 m, required <= 0.003 m");
  ScenarioResult crashed = sample.scenarios[2];
  crashed.error = "hil crashed\nsignal 11";
  EXPECT_EQ(FormatScenarioLine(crashed, 5, 12),
            "[5/12] FAIL no_report 0.05 s: error: hil crashed signal 11");
  EXPECT_EQ(FormatScenarioLine(sample.scenarios[5], 6, 12), "[6/12] PASS deadlines 0.30 s");
}

TEST(CampaignText, Summary) {
  CampaignResult result = SampleCampaign();
  result.name = "smoke";
  result.scenarios = {result.scenarios[0], result.scenarios[2], result.scenarios[3],
                      result.scenarios[4]};
  EXPECT_EQ(FormatCampaignSummary(result),
            "  PASS  step_response\n"
            "  FAIL  no_report      error: hil exited with 4 and wrote no report\n"
            "  PASS  open_loop\n"
            "  FAIL  never_settles  settling_time_s measured inf s, required <= 0.5 s\n"
            "2 passed, 2 failed of 4 (campaign smoke)\n");
  result.scenarios.clear();
  EXPECT_EQ(FormatCampaignSummary(result), "0 passed, 0 failed of 0 (campaign smoke)\n");
}

TEST(CampaignText, NumbersWithTheirUnits) {
  ScenarioResult scenario = Scenario(0, "units", 0.0);
  scenario.criteria = {NumberCriterion("overshoot_pct", "%", "<=", 10.0, 12.345678, false),
                       NumberCriterion("missed_deadlines", "1", "<=", 0.0, 3.0, false),
                       NumberCriterion("credibility_min", "1", ">=", 0.9, 0.81234, false)};
  EXPECT_EQ(FormatScenarioLine(scenario, 1, 1),
            "[1/1] FAIL units 0.00 s: overshoot_pct measured 12.35 %, required <= 10 %; "
            "missed_deadlines measured 3, required <= 0; credibility_min measured 0.8123, "
            "required >= 0.9");
}

}  // namespace campaign_report_test
}  // namespace hiltwin::app
