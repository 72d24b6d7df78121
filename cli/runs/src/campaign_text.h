#pragma once
/// The words every output of `hiltwin test` uses for a criterion and a scenario (the progress
/// line, the summary, the JUnit messages, the HTML table), written once so they cannot drift
/// apart: "tracking_max_m measured 0.0041 m, required <= 0.003 m".

#include <string>

#include "hiltwin/runs/campaign_result.h"

namespace hiltwin::app::campaign_text {

/// "0.0041 m", "12.5 %", "3" (unit "1" and "" print no unit), "inf s": %.4g and the unit.
[[nodiscard]] std::string Quantity(double value, const std::string& unit);

/// "<= 0.003 m", "at most PASS".
[[nodiscard]] std::string Required(const CriterionResult& criterion);

/// "0.0041 m", "FLAGGED", "nothing (the run gave no figure)".
[[nodiscard]] std::string Measured(const CriterionResult& criterion);

/// "measured 0.0041 m, required <= 0.003 m": why a criterion failed, without its name.
[[nodiscard]] std::string Shortfall(const CriterionResult& criterion);

/// A scenario's wall-clock time: "0.41 s".
[[nodiscard]] std::string WallTime(double wall_s);

/// `text` on one line: line breaks and tabs become spaces (an error may quote a program's
/// output).
[[nodiscard]] std::string OneLine(std::string text);

/// Why a failed scenario failed, for one line: "error: TEXT" when it has an error, else
/// "NAME measured X, required Y" per failed criterion, joined with "; ". "" when it passed.
[[nodiscard]] std::string FailureReasons(const ScenarioResult& scenario);

/// "1/3", or "1/3+2/3" for a merged result; "" when there is none.
[[nodiscard]] std::string ShardsLabel(const CampaignResult& result);

}  // namespace hiltwin::app::campaign_text
