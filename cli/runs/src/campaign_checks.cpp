// What a campaign scenario's keys mean together (campaign_checks.h): each refusal names the
// scenario's place in the file, what is wrong and what to do.
#include "campaign_checks.h"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/scheduler/executive.h"

namespace hiltwin::app {
namespace campaign_checks_detail {

namespace fs = std::filesystem;

[[noreturn]] void Refuse(const CampaignScenario& s, const std::string& what) {
  throw CampaignFileError(s.where + ": scenario " + s.name + ": " + what);
}

void CheckRate(const CampaignScenario& s, const char* key, double rate_hz) {
  try {
    scheduler::ValidateRateHz(rate_hz);
  } catch (const std::invalid_argument& e) {
    Refuse(s, std::string(key) + ": " + e.what());
  }
}

void CheckFile(const CampaignScenario& s, const char* key, const std::string& path) {
  if (path.empty()) return;
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    Refuse(s, std::string(key) + " " + path +
                  ": no such file (relative paths are read from the campaign file's folder)");
  }
}

/// lib:PATH and fmu:PATH name files that must exist; the built-in and 20-sim names are checked
/// when the runner pre-flights the controller.
void CheckSpecFile(const CampaignScenario& s, const char* key, const std::string& spec) {
  for (const std::string_view prefix : {"lib:", "fmu:"}) {
    if (spec.starts_with(prefix)) CheckFile(s, key, spec.substr(prefix.size()));
  }
}

bool AsksTracking(const CampaignCriteria& c) {
  return c.tracking_max_m || c.tracking_rms_m || c.final_error_m || c.settling_time_s ||
         c.overshoot_pct;
}

/// A setpoint profile with a sudden step (two knots at one time), for settling and overshoot.
void CheckStep(const CampaignScenario& s) {
  const SetpointProfile profile = LoadSetpointProfile(s.setpoint);
  const auto knots = profile.knots();
  for (std::size_t i = 1; i < knots.size(); ++i) {
    if (knots[i].time_s == knots[i - 1].time_s) return;
  }
  Refuse(s,
         "settling_time_s and overshoot_pct need a setpoint with a step (a CSV with one time "
         "given twice); setpoint " +
             s.setpoint + " has none");
}

void CheckCriteria(const CampaignScenario& s) {
  const CampaignCriteria& c = s.criteria;
  const bool closed_loop = s.kind == "hil" && s.mode == "closedloop";
  if (AsksTracking(c) && !closed_loop) {
    Refuse(s,
           "tracking, final error, settling and overshoot bounds need kind = \"hil\" and "
           "mode = \"closedloop\" (a controller following a setpoint)");
  }
  if (c.duty_saturation_pct && s.kind != "hil") {
    Refuse(s, "duty_saturation_pct needs kind = \"hil\": the ECS's duty is what saturates");
  }
  if (c.settling_time_s || c.overshoot_pct) CheckStep(s);
  if (c.credibility_min && (c.reference_file.empty() || c.reference_column.empty())) {
    Refuse(s,
           "credibility_min needs reference_file and reference_column (the curve the "
           "scenario's compare_column is scored against)");
  }
  if (!c.credibility_min && !c.reference_file.empty()) {
    Refuse(s, "reference_file is given without credibility_min: add the score it must reach");
  }
  if (c.credibility_min && *c.credibility_min > 1.0) {
    Refuse(s, "credibility_min must be at most 1 (assess's score is 0 .. 1)");
  }
  CheckFile(s, "reference_file", c.reference_file);
}

void CheckProfiles(const CampaignScenario& s) {
  try {
    if (s.kind == "hil" && s.mode == "closedloop") {
      static_cast<void>(LoadSetpointProfile(s.setpoint));
    } else {
      static_cast<void>(LoadInputProfile(s.input));
    }
  } catch (const ProfileError& e) {
    Refuse(s, e.what());
  }
}

}  // namespace campaign_checks_detail

void CheckLinkFault(const std::string& spec) {
  using namespace campaign_checks_detail;  // this file's helpers
  static_cast<void>(io::ParseLinkFaultInjection(spec));
}
void CheckOverrun(const std::string& spec) {
  using namespace campaign_checks_detail;  // this file's helpers
  static_cast<void>(runtime::ParseOverrunInjection(spec));
}
void CheckQosRule(const std::string& rule) { static_cast<void>(qos::ParseMkRule(rule)); }

void CheckScenario(const CampaignScenario& s) {
  using namespace campaign_checks_detail;  // this file's helpers
  CheckRate(s, "twin_rate_hz", s.twin_rate_hz);
  CheckRate(s, "ecs_rate_hz", s.ecs_rate_hz);
  if (s.kind == "run" && !s.ecs_overruns.empty()) {
    Refuse(s, "ecs_overruns needs kind = \"hil\" (a run has no ECS)");
  }
  for (const auto& [key, path] : {std::pair{"config", &s.config},
                                  {"gains", &s.gains},
                                  {"controller_map", &s.controller_map},
                                  {"plant_map", &s.plant_map}}) {
    CheckFile(s, key, *path);
  }
  CheckSpecFile(s, "controller", s.controller);
  CheckSpecFile(s, "plant", s.plant);
  if (!s.params.empty() && !s.plant.empty()) {
    Refuse(s, "params are the RELbot's; plant " + s.plant + " takes its own parameters");
  }
  static_cast<void>(ScenarioRelbotParams(s));
  CheckProfiles(s);
  CheckCriteria(s);
}

RelbotParams ScenarioRelbotParams(const CampaignScenario& s) {
  using namespace campaign_checks_detail;  // this file's helpers
  RelbotParams params = DefaultRelbotParams();
  try {
    if (!s.config.empty()) params = LoadRelbotParams(s.config);
  } catch (const ConfigError& e) {
    Refuse(s, e.what());
  }
  for (const auto& [name, value] : s.params) {
    bool found = false;
    for (const ParamSpec& spec : RelbotParamSpecs()) {
      if (name != std::string(spec.table) + "." + std::string(spec.key)) continue;
      params.*spec.member = value;
      found = true;
    }
    if (!found) {
      Refuse(s, "params \"" + name +
                    "\": no such RELbot parameter (\"section.key\" as in "
                    "relbot/relbot.toml, e.g. \"body.mass_kg\")");
    }
  }
  try {
    ValidateRelbotParams(params, "params of scenario " + s.name);
  } catch (const ConfigError& e) {
    Refuse(s, e.what());
  }
  return params;
}

std::string RelbotParamsToml(const RelbotParams& params) {
  using namespace campaign_checks_detail;  // this file's helpers
  std::string text = "# Written by hiltwin test: a scenario's RELbot parameters.\n";
  std::string_view table;
  for (const ParamSpec& spec : RelbotParamSpecs()) {
    if (spec.table != table) {
      table = spec.table;
      text += "\n[" + std::string(table) + "]\n";
    }
    // The shortest exact form may be "2" or "1e-06": TOML needs a float to look like one.
    std::string value = ExactNum(params.*spec.member);
    if (value.find_first_of(".eEn") == std::string::npos) value += ".0";
    text += std::string(spec.key) + " = " + value + "\n";
  }
  return text;
}

}  // namespace hiltwin::app
