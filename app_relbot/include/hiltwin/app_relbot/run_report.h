#pragma once
/// The run report (DESIGN.md "Run report"): built after the loop from the executive's
/// statistics, the QoS monitor and the logger, written as JSON and summarised on stdout.

#include <nlohmann/json.hpp>
#include <cstdint>
#include <string>

#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/scheduler/executive.h"

namespace hiltwin::app {

/// Everything the report says beyond what the executive and the monitor hold.
struct RunFacts {
  std::string stop_reason;       ///< statemachine stop reason ("finished", "stop_requested", ...)
  std::string clock;             ///< "realtime" / "virtual"
  std::string io;                ///< backend spec, e.g. "mock"
  std::string input;             ///< profile name or CSV path
  std::string integrator;        ///< "rk4", ...
  double rate_hz = 0.0;
  std::uint64_t cycles_planned = 0;
  std::uint64_t log_rows_written = 0;
  std::uint64_t log_rows_dropped = 0;
  std::string log_path;          ///< empty: no log
  std::uint64_t io_errors = 0;   ///< corrupted or missed frames
  std::uint64_t counts_over_limit = 0;  ///< encoder changes above what one period can emit
  std::uint64_t controller_absent_cycles = 0;  ///< wire: cycles with no controller attached
  double wall_time_s = 0.0;      ///< how long the run took on the monotonic clock
};

/// Builds the JSON report. Keys of DESIGN.md's contract come first and keep their names.
[[nodiscard]] nlohmann::ordered_json BuildRunReport(const RunFacts& facts,
                                            const scheduler::Executive& executive,
                                            const qos::QosMonitor& monitor,
                                            const kernel_glue::RtSetupRecord& rt);

/// A short human summary of a report for stdout (a few lines, ends with the verdict).
[[nodiscard]] std::string FormatRunSummary(const nlohmann::ordered_json& report);

}  // namespace hiltwin::app
