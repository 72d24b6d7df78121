#include "hiltwin/telemetry/record_json.h"

#include <cstddef>

#include "hiltwin/telemetry/codes.h"

namespace hiltwin::telemetry {
namespace {

nlohmann::ordered_json WheelsJson(const runtime::TelemetryRecord& r) {
  nlohmann::ordered_json wheels = nlohmann::ordered_json::object();
  const std::size_t n = r.task.joint_count;
  for (std::size_t i = 0; i < n && i < r.joint_names.size(); ++i) {
    wheels[r.joint_names[i]] = {{"rad", r.task.joint_position_rad[i]},
                                {"m", r.task.joint_position_m[i]}};
  }
  return wheels;
}

nlohmann::ordered_json SetpointJson(const runtime::TelemetryRecord& r) {
  nlohmann::ordered_json setpoint = nlohmann::ordered_json::object();
  const std::size_t n = r.task.joint_count;
  for (std::size_t i = 0; i < n && i < r.joint_names.size(); ++i) {
    setpoint[r.joint_names[i]] = {{"m", r.task.joint_setpoint_m[i]}};
  }
  return setpoint;
}

nlohmann::ordered_json TimingJson(const runtime::TelemetryRecord& r) {
  nlohmann::ordered_json timing = {
      {"rate_hz", r.rate_hz},
      {"cycles_planned", r.cycles_planned},
      {"deadline_misses", r.deadline_misses},
      {"latency_p99_us", r.latency_p99_us},
      {"latency_max_us", r.latency_max_us},
      {"latency_samples", r.latency_samples},
      {"distance_to_violation", nullptr},
      {"verdict", qos::ToString(r.verdict_so_far)},
      {"verdict_code", VerdictCode(r.verdict_so_far)},  // PlotJuggler plots numbers only
  };
  if (r.distance_to_violation) timing["distance_to_violation"] = *r.distance_to_violation;
  return timing;
}

}  // namespace

nlohmann::ordered_json ToJson(const runtime::TelemetryRecord& r) {
  nlohmann::ordered_json j = {
      {"timestamp", r.time_s},
      {"ns", r.ns},
      {"role", r.role},
      {"cycle", r.cycle},
      {"state", lifecycle::ToString(r.state)},
      {"state_code", StateCode(r.state)},
      {"final", r.final},
  };
  if (r.task.has_pose) {
    j["pose"] = {{"x", r.task.x_m}, {"y", r.task.y_m}, {"theta", r.task.theta_rad}};
  }
  j["wheels"] = WheelsJson(r);
  if (r.task.has_setpoint) j["setpoint"] = SetpointJson(r);
  j["timing"] = TimingJson(r);
  return j;
}

}  // namespace hiltwin::telemetry
