#pragma once
/// `hiltwin hil`'s combined result: the twin's and the ECS's run reports (read back from the
/// files the two processes wrote), how each process ended, the tracking error and the link
/// errors. One typed record (HilResult) from which the JSON report, the summary and the exit
/// code all derive. Pure: no processes or files here, so it is tested with plain inputs.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/kernel_glue/process.h"

namespace hiltwin::app {

/// One process of the pair after it ended.
struct HilSide {
  std::string name;                              ///< "twin" or "ecs"
  kernel_glue::ExitStatus status;                ///< how the process ended
  std::optional<nlohmann::ordered_json> report;  ///< its run report, when it wrote one
};

/// Closed-loop tracking error of both wheels (from the ECS's report), in metres.
struct HilTracking {
  double max_left_m = 0.0;
  double max_right_m = 0.0;
  double rms_m = 0.0;
  double final_m = 0.0;  ///< the larger |final error| of the two wheels
};

/// Everything that went wrong on the link, summed over both sides.
struct HilLinkErrors {
  std::uint64_t twin_frames = 0;          ///< frames the twin saw corrupted or missed
  std::uint64_t ecs_frames = 0;           ///< frames the ECS saw corrupted or missed
  std::uint64_t encoder_line_errors = 0;  ///< illegal transitions + too-fast edges + resyncs
  [[nodiscard]] std::uint64_t total() const noexcept {
    return twin_frames + ecs_frames + encoder_line_errors;
  }
};

struct HilResult {
  std::string wire;  ///< wire:NAME both processes used
  std::string mode;  ///< closedloop / openloop
  HilSide twin;
  HilSide ecs;
  std::optional<HilTracking> tracking;  ///< closed loop with an ECS report
  HilLinkErrors link;
  int exit_code = 0;  ///< the worse of the two, or the failed side's when the other echoes it
  /// What `hil` found doubtful about the pair before it started them (e.g. an --ecs-rate too
  /// slow to follow the twin's encoders; relbot/encoder_reading.h).
  std::vector<std::string> warnings;
};

/// The exit code a process's status stands for: its code, or 1 (internal) for a signal.
[[nodiscard]] int ExitCodeOf(const kernel_glue::ExitStatus& status) noexcept;

/// The worse of two exit codes, from best to worst: 0 pass, 3 flagged, 4 aborted, 128 + a
/// signal (stopped before any cycle was judged: no verdict), 5 I/O, 2 usage (the run could not
/// happen as asked), 1 internal (crash, model fault).
[[nodiscard]] int WorseExitCode(int a, int b) noexcept;

/// Combines the two sides. Reports that lack a key the ECS/twin always write are read as
/// absent figures, not as errors.
[[nodiscard]] HilResult CombineHil(std::string wire, std::string mode, HilSide twin, HilSide ecs);

/// The combined JSON report: `twin`, `ecs` (each the full run report, null when missing),
/// `tracking_error_max_m` {left, right}, `tracking_error_rms_m`, `final_error_m` (null in open
/// loop), `link_errors` and its parts, each side's exit, the combined `exit_code`, `warnings`.
[[nodiscard]] nlohmann::ordered_json ToJson(const HilResult& result);

/// The combined summary: one line per side, tracking, link, and the combined exit.
[[nodiscard]] std::string FormatHilSummary(const HilResult& result);

}  // namespace hiltwin::app
