#include "hiltwin/relbot/ecs_report.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace hiltwin::app {

EcsFigures EcsFiguresOf(const EcsTask& task, const io::IcoBoardLink& driver,
                        const io::EmulatedFpga* board) {
  EcsFigures figures;
  figures.mode = task.mode();
  figures.tracking = task.tracking();
  figures.link = driver.counters();
  if (board != nullptr) figures.encoder_lines = board->encoder_lines().counters();
  if (const controller::ControllerTask* loop = task.controller_task()) {
    figures.controller = loop->controller().Info();
    figures.fault = loop->fault();
    figures.pairs = loop->tracking();
  }
  return figures;
}

namespace {

using Json = nlohmann::ordered_json;

const char* ToString(controller::ControllerFault::Kind kind) {
  switch (kind) {
    case controller::ControllerFault::Kind::kErrorStatus:
      return "error status";
    case controller::ControllerFault::Kind::kNotFinite:
      return "not finite";
    case controller::ControllerFault::Kind::kBeyondLimit:
      return "beyond duty_limit";
    case controller::ControllerFault::Kind::kNone:
      break;
  }
  return "none";
}

Json PortsJson(const std::vector<controller::Port>& ports) {
  Json out = Json::array();
  for (const controller::Port& port : ports) {
    out.push_back({{"name", port.name}, {"unit", port.unit}});
  }
  return out;
}

Json FaultJson(const controller::ControllerFault& f) {
  if (f.kind == controller::ControllerFault::Kind::kNone) return nullptr;
  // A non-finite value is not JSON: its text instead.
  const Json value = std::isfinite(f.value) ? Json(f.value) : Json(std::to_string(f.value));
  return {{"kind", ToString(f.kind)}, {"output", f.output},         {"value", value},
          {"duty_limit", f.duty_limit}, {"reason", f.reason}, {"cycle", f.cycle}};
}

Json PairsJson(const EcsFigures& f) {
  if (!f.controller) return nullptr;
  Json out = Json::array();
  for (const controller::TrackingPair& p : f.pairs) {
    out.push_back({{"column", p.column},
                   {"input", p.input},
                   {"tracks", p.tracked},
                   {"samples", p.samples},
                   {"max_abs_error", p.max_abs_error},
                   {"rms_error", p.rms_error},
                   {"final_error", p.final_error}});
  }
  return out;
}

Json ControllerJson(const EcsFigures& f) {
  if (!f.controller) return nullptr;
  const controller::ControllerInfo& c = *f.controller;
  Json details = Json::object();
  for (const auto& [key, value] : c.details) details[key] = value;
  return {{"spec", c.spec},
          {"kind", c.kind},
          {"name", c.name},
          {"file", c.file},
          {"content_sha256", c.content_sha256},
          {"inputs", PortsJson(c.inputs)},
          {"outputs", PortsJson(c.outputs)},
          {"model_step_s", c.model_step_s},
          {"details", details},
          {"fault", FaultJson(f.fault)}};
}

}  // namespace

nlohmann::ordered_json EcsReportJson(const runtime::RunReport& report, const EcsFigures& f) {
  Json json = runtime::ToJson(report);
  const TrackingStats& t = f.tracking;
  json["tracking"] =
      f.mode == EcsMode::kOpenLoop
          ? Json(nullptr)
          : Json{{"samples", t.samples},
                 {"max_abs_error_m", {{"left", t.max_abs_error_left_m},
                                      {"right", t.max_abs_error_right_m}}},
                 {"rms_error_m", t.rms_error_m},
                 {"rms_error_wheel_m", {{"left", t.rms_error_left_m},
                                        {"right", t.rms_error_right_m}}},
                 {"final_error_m", {{"left", t.final_error_left_m},
                                    {"right", t.final_error_right_m}}},
                 {"saturated_cycles", t.saturated_cycles},
                 {"max_abs_duty", t.max_abs_duty}};
  json["controller"] = ControllerJson(f);
  json["tracking_pairs"] = PairsJson(f);
  const io::LinkCounters& l = f.link;
  json["link_counters"] = {{"frames_sent", l.frames_sent},
                           {"frames_received", l.frames_received},
                           {"frames_corrupted", l.frames_corrupted},
                           {"frames_missed", l.frames_missed},
                           {"faults", l.faults}};
  if (f.encoder_lines) {
    const io::EncoderLineCounters& e = *f.encoder_lines;
    json["encoder_lines"] = {{"edges", e.edges},
                             {"illegal_transitions", e.illegal_transitions},
                             {"too_fast_edges", e.too_fast_edges},
                             {"resyncs", e.resyncs}};
  } else {
    json["encoder_lines"] = nullptr;
  }
  return json;
}

std::string FormatEcsFigures(const EcsFigures& f) {
  char text[512];
  std::string out;
  if (f.mode == EcsMode::kClosedLoop) {
    const TrackingStats& t = f.tracking;
    std::snprintf(text, sizeof text,
                  "tracking   max |error| left %.3f mm, right %.3f mm; rms %.3f mm; final left "
                  "%.3f mm, right %.3f mm; duty saturated in %llu cycles\n",
                  t.max_abs_error_left_m * 1e3, t.max_abs_error_right_m * 1e3,
                  t.rms_error_m * 1e3, t.final_error_left_m * 1e3, t.final_error_right_m * 1e3,
                  static_cast<unsigned long long>(t.saturated_cycles));
    out += text;
  }
  if (f.fault.kind != controller::ControllerFault::Kind::kNone && f.controller) {
    out += "controller " + f.controller->spec + " stopped at cycle " +
           std::to_string(f.fault.cycle) + ": " + ToString(f.fault.kind) +
           (f.fault.output.empty() ? "" : " on output " + f.fault.output) +
           (f.fault.reason.empty() ? "" : " (" + f.fault.reason + ")") + "; safe outputs\n";
  }
  if (f.encoder_lines) {
    const io::EncoderLineCounters& e = *f.encoder_lines;
    std::snprintf(text, sizeof text,
                  "encoders   %llu edges decoded; %llu illegal transitions, %llu too fast, %llu "
                  "resyncs\n",
                  static_cast<unsigned long long>(e.edges),
                  static_cast<unsigned long long>(e.illegal_transitions),
                  static_cast<unsigned long long>(e.too_fast_edges),
                  static_cast<unsigned long long>(e.resyncs));
    out += text;
  }
  return out;
}

}  // namespace hiltwin::app
