#include "hiltwin/relbot/ecs_report.h"

#include <cstdio>

namespace hiltwin::app {

EcsFigures EcsFiguresOf(const EcsTask& task, const io::IcoBoardLink& driver,
                        const io::EmulatedFpga* board) {
  EcsFigures figures;
  figures.mode = task.mode();
  figures.tracking = task.tracking();
  figures.link = driver.counters();
  if (board != nullptr) figures.encoder_lines = board->encoder_lines().counters();
  return figures;
}

nlohmann::ordered_json EcsReportJson(const runtime::RunReport& report, const EcsFigures& f) {
  using Json = nlohmann::ordered_json;
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
