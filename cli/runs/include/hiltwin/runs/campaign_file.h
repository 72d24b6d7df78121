#pragma once
/// `hiltwin test`'s campaign file (TOML, docs/testing-campaigns.md): a `[campaign]` table, a
/// `[defaults]` table that every scenario starts from, and `[[scenario]]` tables, each a run of
/// `hiltwin hil` (the controller in the loop) or `hiltwin run` (the twin alone) with its
/// criteria. Every key is checked when the file is read: an unknown key, a wrong type, a value
/// out of range, a flag string the command would refuse (a link fault, an overrun, a QoS rule)
/// or a missing file is refused with file:line:col before any scenario runs.

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hiltwin/runs/campaign_criteria.h"

namespace hiltwin::app {

/// A campaign file that cannot be used: "FILE:LINE:COL: what is wrong; what to do".
class CampaignFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One scenario, with the defaults applied and every path made absolute (relative paths are
/// read from the campaign file's folder).
struct CampaignScenario {
  std::size_t index = 0;            ///< 0-based position in the file
  std::string name;                 ///< unique; letters, digits, '_', '-', '.'
  std::string kind = "hil";         ///< "hil": twin + ECS; "run": the twin alone (open loop)
  std::string clock = "virtual";    ///< "virtual" (lockstep, exact) or "realtime"
  std::string mode = "closedloop";  ///< hil: closedloop (controller on setpoint) or openloop
  std::string controller = "pid";   ///< hil closedloop: the ECS's --controller
  std::string controller_map;       ///< "": the RELbot's
  std::string gains;                ///< --controller pid's gains file; "": the built-in
  std::string plant;                ///< the twin's --plant; "": the RELbot
  std::string plant_map;            ///< the twin's --plant-map; "": the plant's own
  std::string config;               ///< RELbot parameter file; "": the built-in parameters
  /// Parameter overrides, "section.key" -> value in the parameter file's unit, applied to
  /// `config` (or the built-in set); written to the scenario's own parameter file.
  std::map<std::string, double> params;
  std::string setpoint = "closedloop";  ///< closed loop: built-in name or CSV path
  std::string input = "openloop";       ///< open loop: built-in name or CSV path
  double twin_rate_hz = 4000.0;
  double ecs_rate_hz = 1000.0;  ///< hil: the ECS's rate; run: the input's rate (--input-rate)
  double duration_s = 0.0;      ///< 0: the profile's length
  std::vector<std::string> link_faults;    ///< the twin's --inject-link-fault, each
  std::vector<std::string> twin_overruns;  ///< the twin's --inject-overrun, each
  std::vector<std::string> ecs_overruns;   ///< the ECS's --inject-overrun, each (hil)
  std::vector<std::string> twin_qos;       ///< the twin's --qos M:K rules (none: its defaults)
  std::vector<std::string> ecs_qos;        ///< the ECS's --qos rules (hil)
  std::optional<double> twin_max_miss_pct;
  std::optional<double> ecs_max_miss_pct;
  CampaignCriteria criteria;
  /// The file:line:col where the scenario's table begins, for messages about it.
  std::string where;
};

struct Campaign {
  std::string file;  ///< as given
  std::string name;  ///< [campaign] name, or the file's stem
  std::string description;
  std::vector<CampaignScenario> scenarios;
};

/// Reads and checks a campaign file. Throws CampaignFileError.
[[nodiscard]] Campaign LoadCampaign(const std::string& path);
/// The same from text; `source` names it in messages and `folder` is where relative paths are
/// read from.
[[nodiscard]] Campaign ParseCampaign(const std::string& text, const std::string& source,
                                     const std::string& folder);

}  // namespace hiltwin::app
