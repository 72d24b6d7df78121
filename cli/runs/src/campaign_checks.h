#pragma once
// What a campaign scenario's keys mean together, checked when the file is read (exit 2 before
// any scenario runs), and the scenario's RELbot parameters with its overrides applied.
#include <string>

#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/runs/campaign_file.h"

namespace hiltwin::app {

/// The flag strings' checks, by the parsers the commands use (std::invalid_argument).
void CheckLinkFault(const std::string& spec);
void CheckOverrun(const std::string& spec);
void CheckQosRule(const std::string& rule);

/// Throws CampaignFileError "WHERE: scenario NAME: what; what to do" for rates out of range,
/// a criterion the scenario's kind or mode cannot measure, a settling or overshoot bound on a
/// setpoint without a step, a credibility bound without its reference (or the reverse), an
/// unknown parameter override, a missing file, a profile that does not load.
void CheckScenario(const CampaignScenario& s);

/// `config` (or the built-in set) with `params` applied. Throws CampaignFileError.
[[nodiscard]] RelbotParams ScenarioRelbotParams(const CampaignScenario& s);

/// A RELbot parameter file holding `params`, every key in file order, each value exact.
[[nodiscard]] std::string RelbotParamsToml(const RelbotParams& params);

}  // namespace hiltwin::app
