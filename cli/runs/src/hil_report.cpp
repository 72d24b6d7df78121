#include "hiltwin/runs/hil_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace hiltwin::app {
namespace {

using Json = nlohmann::ordered_json;

/// Position of an exit code from best (0) to worst.
int Severity(int code) noexcept {
  switch (code) {
    case 0: return 0;  // pass
    case 3: return 1;  // flagged
    case 4: return 2;  // aborted
    case 5: return 4;  // I/O
    case 2: return 5;  // usage
    default:
      // 129..159: stopped by a signal before any cycle was judged (no verdict, nothing failed)
      if (code > 128 && code < 160) return 3;
      return 6;  // 1 internal, and anything unknown
  }
}

std::uint64_t U64At(const std::optional<Json>& report, const Json::json_pointer& where) {
  if (!report || !report->contains(where) || !report->at(where).is_number()) return 0;
  return report->at(where).get<std::uint64_t>();
}

double DoubleAt(const Json& json, const Json::json_pointer& where) {
  return json.contains(where) && json.at(where).is_number() ? json.at(where).get<double>()
                                                            : std::numeric_limits<double>::quiet_NaN();
}

std::optional<HilTracking> TrackingOf(const std::optional<Json>& ecs) {
  if (!ecs || !ecs->contains("tracking") || !(*ecs)["tracking"].is_object()) return std::nullopt;
  const Json& t = (*ecs)["tracking"];
  HilTracking tracking;
  tracking.max_left_m = DoubleAt(t, Json::json_pointer("/max_abs_error_m/left"));
  tracking.max_right_m = DoubleAt(t, Json::json_pointer("/max_abs_error_m/right"));
  tracking.rms_m = DoubleAt(t, Json::json_pointer("/rms_error_m"));
  tracking.final_m = std::max(std::abs(DoubleAt(t, Json::json_pointer("/final_error_m/left"))),
                              std::abs(DoubleAt(t, Json::json_pointer("/final_error_m/right"))));
  return tracking;
}

/// The ECS report's `controller` section (closed loop), or null.
Json ControllerOf(const HilSide& ecs) {
  if (!ecs.report || !ecs.report->contains("controller")) return nullptr;
  return (*ecs.report)["controller"];
}

/// "controller pid (built-in): pid" and, for code from a file, its path and SHA-256: which code
/// produced the result.
std::string ControllerLine(const Json& c) {
  if (!c.is_object()) return "";
  const auto text = [&c](const char* key) {
    return c.contains(key) && c[key].is_string() ? c[key].get<std::string>() : std::string();
  };
  std::string line = "controller " + text("spec") + " (" + text("kind") + "): " + text("name");
  if (!text("file").empty()) line += "; " + text("file") + ", sha256 " + text("content_sha256");
  // A controller the ECS stopped: the pair's summary says so where it names the controller,
  // as the ECS's own summary does (ecs_report.cpp).
  if (c.contains("fault") && c["fault"].is_object()) {
    const Json& f = c["fault"];
    const auto field = [&f](const char* key) {
      return f.contains(key) && f[key].is_string() ? f[key].get<std::string>() : std::string();
    };
    line += "; stopped at cycle " + std::to_string(f.value("cycle", 0ULL)) + ": " + field("kind");
    if (!field("output").empty()) line += " on output " + field("output");
    if (!field("reason").empty()) line += " (" + field("reason") + ")";
  }
  return line + "\n";
}

Json SideExit(const HilSide& side) {
  return {{"exit_code", ExitCodeOf(side.status)}, {"ended", side.status.Describe()}};
}

std::string SideLine(const HilSide& side) {
  char text[400];
  if (!side.report) {
    std::snprintf(text, sizeof text, "%-5s no report (%s)\n", side.name.c_str(),
                  side.status.Describe().c_str());
    return text;
  }
  const Json& r = *side.report;
  std::snprintf(text, sizeof text,
                "%-5s %-8s stop %-15s %llu cycles at %.0f Hz, %llu misses (%.4f %%), %s\n",
                side.name.c_str(), r.value("verdict", "?").c_str(),
                r.value("stop_reason", "?").c_str(),
                static_cast<unsigned long long>(r.value("cycles_run", 0ULL)),
                r.value("rate_hz", 0.0),
                static_cast<unsigned long long>(r.value("deadline_misses", 0ULL)),
                r.value("miss_pct", 0.0), side.status.Describe().c_str());
  return text;
}

}  // namespace

int ExitCodeOf(const kernel_glue::ExitStatus& status) noexcept {
  return status.exited ? status.code : 1;
}

int WorseExitCode(int a, int b) noexcept { return Severity(a) >= Severity(b) ? a : b; }

namespace {

/// "5", or "1, killed by signal 11 (SIGSEGV)": a side that did not exit counts as 1, and the
/// summary says why rather than an exit code the side never gave.
std::string CodeText(const kernel_glue::ExitStatus& status) {
  const std::string code = std::to_string(ExitCodeOf(status));
  return status.exited ? code : code + ", " + status.Describe();
}

/// A side that judged no cycle because its peer ended first (verdict NONE, stop peer_stopped)
/// only echoes that peer's end: its exit 5 says nothing the peer's own code does not.
bool EchoesItsPeer(const HilSide& side) {
  return side.report && side.report->value("verdict", "") == "NONE" &&
         side.report->value("stop_reason", "") == "peer_stopped";
}

/// The pair's exit code: the worse of the two, except that a side echoing a peer that failed
/// (a QoS abort in the twin's first cycles, say) leaves the code to the peer, which says why.
int PairExitCode(const HilSide& twin, const HilSide& ecs) {
  const int twin_code = ExitCodeOf(twin.status);
  const int ecs_code = ExitCodeOf(ecs.status);
  if (EchoesItsPeer(ecs) && !EchoesItsPeer(twin) && twin_code != 0) return twin_code;
  if (EchoesItsPeer(twin) && !EchoesItsPeer(ecs) && ecs_code != 0) return ecs_code;
  return WorseExitCode(twin_code, ecs_code);
}

}  // namespace

HilResult CombineHil(std::string wire, std::string mode, HilSide twin, HilSide ecs) {
  HilResult result;
  result.wire = std::move(wire);
  result.mode = std::move(mode);
  result.tracking = TrackingOf(ecs.report);
  result.link.twin_frames = U64At(twin.report, Json::json_pointer("/io_errors"));
  result.link.ecs_frames = U64At(ecs.report, Json::json_pointer("/io_errors"));
  result.link.encoder_line_errors =
      U64At(ecs.report, Json::json_pointer("/encoder_lines/illegal_transitions")) +
      U64At(ecs.report, Json::json_pointer("/encoder_lines/too_fast_edges")) +
      U64At(ecs.report, Json::json_pointer("/encoder_lines/resyncs"));
  result.exit_code = PairExitCode(twin, ecs);
  result.twin = std::move(twin);
  result.ecs = std::move(ecs);
  return result;
}

Json ToJson(const HilResult& r) {
  Json json;
  json["exit_code"] = r.exit_code;
  json["wire"] = r.wire;
  json["mode"] = r.mode;
  json["controller"] = ControllerOf(r.ecs);
  if (r.tracking) {
    json["tracking_error_max_m"] = {{"left", r.tracking->max_left_m},
                                    {"right", r.tracking->max_right_m}};
    json["tracking_error_rms_m"] = r.tracking->rms_m;
    json["final_error_m"] = r.tracking->final_m;
  } else {
    json["tracking_error_max_m"] = nullptr;
    json["tracking_error_rms_m"] = nullptr;
    json["final_error_m"] = nullptr;
  }
  json["link_errors"] = r.link.total();
  json["link_error_parts"] = {{"twin_frames_corrupted_or_missed", r.link.twin_frames},
                              {"ecs_frames_corrupted_or_missed", r.link.ecs_frames},
                              {"encoder_line_errors", r.link.encoder_line_errors}};
  json["warnings"] = r.warnings;
  json["twin_exit"] = SideExit(r.twin);
  json["ecs_exit"] = SideExit(r.ecs);
  json["twin"] = r.twin.report ? *r.twin.report : Json(nullptr);
  json["ecs"] = r.ecs.report ? *r.ecs.report : Json(nullptr);
  return json;
}

std::string FormatHilSummary(const HilResult& r) {
  std::string out = SideLine(r.twin) + SideLine(r.ecs) + ControllerLine(ControllerOf(r.ecs));
  char text[400];
  if (r.tracking) {
    std::snprintf(text, sizeof text,
                  "tracking  max |error| left %.3f mm, right %.3f mm; rms %.3f mm; final %.3f mm\n",
                  r.tracking->max_left_m * 1e3, r.tracking->max_right_m * 1e3,
                  r.tracking->rms_m * 1e3, r.tracking->final_m * 1e3);
    out += text;
  }
  std::snprintf(text, sizeof text,
                "link      %llu errors (twin frames %llu, ECS frames %llu, encoder lines %llu)\n",
                static_cast<unsigned long long>(r.link.total()),
                static_cast<unsigned long long>(r.link.twin_frames),
                static_cast<unsigned long long>(r.link.ecs_frames),
                static_cast<unsigned long long>(r.link.encoder_line_errors));
  out += text;
  for (const std::string& warning : r.warnings) out += "warning   " + warning + "\n";
  const int twin_code = ExitCodeOf(r.twin.status);
  const int ecs_code = ExitCodeOf(r.ecs.status);
  const bool worse = r.exit_code == WorseExitCode(twin_code, ecs_code);
  std::snprintf(text, sizeof text, "hil       exit %d (%s twin %s and ECS %s)\n", r.exit_code,
                worse ? "the worse of" : "the side that failed first of",
                CodeText(r.twin.status).c_str(), CodeText(r.ecs.status).c_str());
  return out + text;
}

}  // namespace hiltwin::app
