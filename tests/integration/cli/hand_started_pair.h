#pragma once
// `hiltwin run` and `hiltwin ecs` started by hand on one wire, one after the other, as README's
// pair is (issue 34, 1): the first side is already waiting for its peer when the second starts,
// so the second's start-up (INIT, then its real-time set-up) happens beside a side that is
// ready to go. Shared by the quick suite's few runs (hil_cli_test.cpp) and the long run beside
// stress-ng (wire_start_load_test.cpp).

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/wire_scratch.h"

namespace hiltwin::test {

/// One hand-started pair: which side starts first and how long each side's --duration is.
/// The second side's run is the shorter: it finishes, and the first then stops because its
/// peer had (peer_stopped).
struct HandStartedPair {
  bool twin_first = true;
  double first_s = 2.0;
  double second_s = 0.3;
};

namespace detail {
inline std::string ReadWhole(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline std::string StopReasonIn(const std::string& report_path) {
  std::ifstream in(report_path);
  if (!in) return "(no report)";
  const nlohmann::json report = nlohmann::json::parse(in, nullptr, false);
  if (report.is_discarded() || !report.contains("stop_reason")) return "(no stop_reason)";
  return report["stop_reason"].get<std::string>();
}

inline bool FlaggedOrPassed(int code) { return code == 0 || code == 3; }
}  // namespace detail

/// Runs `pair` with `binary` on `scratch`'s wire, its files named after `tag`: "" when both
/// sides ended as a pair should (exit 0 or 3 each, the second `finished`, the first
/// `peer_stopped`, no segment left), else what went wrong with both sides' stderr.
inline std::string RunHandStartedPair(const std::string& binary, const WireScratch& scratch,
                                      const std::string& tag, const HandStartedPair& pair) {
  const char* const first = pair.twin_first ? "run" : "ecs";
  const char* const second = pair.twin_first ? "ecs" : "run";
  const std::string first_report = scratch.Path(tag + "-first.json");
  const std::string second_report = scratch.Path(tag + "-second.json");
  const std::string first_out = scratch.Path(tag + "-first.out");
  const auto side = [&](const char* command, double seconds, const std::string& report) {
    return std::vector<std::string>{binary, command, "--io", scratch.Wire(), "--duration",
                                    std::to_string(seconds), "--wait-peer", "10",
                                    "--no-progress", "--report", report};
  };
  kernel_glue::Process first_process =
      Spawn(side(first, pair.first_s, first_report), first_out);
  // The first side's countdown: its set-up is done and it polls for its peer.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (detail::ReadWhole(first_out + ".err").find("waiting for the") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const RunResult second_run = Run(side(second, pair.second_s, second_report), 60'000);
  const auto first_status = first_process.WaitFor(std::chrono::seconds(20));
  const int first_code = first_status ? first_status->code : -1;
  const std::string first_reason = detail::StopReasonIn(first_report);
  const std::string second_reason = detail::StopReasonIn(second_report);
  const bool segment_left = std::filesystem::exists(scratch.SegmentPath());
  if (segment_left) std::filesystem::remove(scratch.SegmentPath());  // the next run starts clean
  if (detail::FlaggedOrPassed(first_code) && detail::FlaggedOrPassed(second_run.exit_code) &&
      first_reason == "peer_stopped" && second_reason == "finished" && !segment_left) {
    return "";
  }
  return std::string(first) + " first: " + first + " exit " + std::to_string(first_code) +
         " (" + first_reason + "), " + second + " exit " + std::to_string(second_run.exit_code) +
         " (" + second_reason + ")" + (segment_left ? ", segment left behind" : "") + "\n" +
         first + " stderr:\n" + detail::ReadWhole(first_out + ".err") + second + " stderr:\n" +
         second_run.err;
}

}  // namespace hiltwin::test
