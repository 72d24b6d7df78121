#pragma once
/// The telemetry record as JSON: the one shape the UDP stream, the web page's event stream and
/// `hiltwin monitor --json` share (docs/telemetry.md lists the keys).
///
///   {"timestamp": 1.25, "ns": "twin", "role": "twin", "cycle": 5000, "state": "run",
///    "final": false,
///    "pose": {"x": 0.1, "y": 0.0, "theta": 0.02},                      (twins only)
///    "wheels": {"wheel_left": {"rad": 1.2, "m": 0.12}, ...},
///    "timing": {"rate_hz": 4000, "cycles_planned": 40000, "deadline_misses": 0,
///               "latency_p99_us": 12.5, "latency_max_us": 30.1, "latency_samples": 4000,
///               "distance_to_violation": 3, "verdict": "PASS"}}
///
/// "timestamp" is the task's time in seconds (the CSV log's time_s), so a PlotJuggler plot
/// and the log line up. "distance_to_violation" is null when no rule can fail.

#include <nlohmann/json.hpp>

#include "hiltwin/runtime/telemetry.h"

namespace hiltwin::telemetry {

[[nodiscard]] nlohmann::ordered_json ToJson(const runtime::TelemetryRecord& record);

}  // namespace hiltwin::telemetry
