#include "hiltwin/runs/campaign_result.h"

#include <algorithm>

namespace hiltwin::app {

bool ScenarioResult::passed() const noexcept {
  return error.empty() &&
         std::all_of(criteria.begin(), criteria.end(),
                     [](const CriterionResult& criterion) { return criterion.passed; });
}

std::size_t CampaignResult::failed() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(scenarios.begin(), scenarios.end(),
                    [](const ScenarioResult& scenario) { return !scenario.passed(); }));
}

int CampaignResult::exit_code() const noexcept { return failed() == 0 ? 0 : 3; }

}  // namespace hiltwin::app
