#pragma once
/// What the ECS adds to its run report: the closed-loop tracking error, the link's frame
/// counters and, on an emulated board, the quadrature readers' error counters. One typed record
/// (EcsFigures), from which the JSON section and the summary lines are both derived; `hiltwin
/// hil` reads the JSON keys back from the ECS's report file.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_task.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_lines.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/relbot/ecs_task.h"
#include "hiltwin/runtime/run_report.h"

namespace hiltwin::app {

struct EcsFigures {
  EcsMode mode = EcsMode::kClosedLoop;
  TrackingStats tracking;
  io::LinkCounters link;
  std::optional<io::EncoderLineCounters> encoder_lines;  ///< emulated boards only
  /// Closed loop: the controller that ran, and why it was stopped (kind kNone: it was not).
  std::optional<controller::ControllerInfo> controller;
  controller::ControllerFault fault;
  /// Closed loop: the tracking error of each `tracks` pair of the controller map.
  std::vector<controller::TrackingPair> pairs;
};

/// Collects the figures after the run (the loop has stopped).
[[nodiscard]] EcsFigures EcsFiguresOf(const EcsTask& task, const io::IcoBoardLink& driver,
                                      const io::EmulatedFpga* board);

/// The run report's JSON with the ECS's sections: `tracking` (closed loop: `max_abs_error_m`
/// {left, right}, `rms_error_m`, `final_error_m` {left, right}, `saturated_cycles`,
/// `max_abs_duty`; null in open loop), `controller` (closed loop: `spec`, `kind`, `name`,
/// `file`, `content_sha256`, `inputs` and `outputs` [{name, unit}], `model_step_s`, `details`,
/// `fault`: null, or {`kind`, `output`, `value`, `duty_limit`, `reason`, `cycle`}; null in open
/// loop), `tracking_pairs` (closed loop: per `tracks` pair of the map, {`column`, `input`,
/// `tracks`, `samples`, `max_abs_error`, `rms_error`, `final_error`}, in the pair's unit; null
/// in open loop), `link_counters` and `encoder_lines` (null on spidev).
[[nodiscard]] nlohmann::ordered_json EcsReportJson(const runtime::RunReport& report,
                                                   const EcsFigures& figures);

/// Summary lines printed before the run summary ("tracking  ..." in closed loop, "controller
/// stopped ..." when it was).
[[nodiscard]] std::string FormatEcsFigures(const EcsFigures& figures);

}  // namespace hiltwin::app
