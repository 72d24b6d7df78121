#pragma once
/// `hiltwin tune`: the twin's update rate chosen the way thesis §3.8.2 (method 2) and
/// Table 5.1 did it by hand, as one procedure (docs/tuning.md):
///   measure   the model step's cost, the loop's own overhead per cycle, the wake-up latency
///             at each candidate rate, and the machine findings that matter;
///   recommend 75 % of 1/(overhead + compute), clamped to 4-10x the controller rate, raised to
///             the accuracy bound where the timing allows (hiltwin/tuning/tuning.h);
///   validate  a run at every candidate and the recommended rate: misses, QoS verdict and the
///             RMS wheel-position error the controller sees against the reference.
/// Every run goes through the shared run assembly with the same twin `hiltwin run` builds.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/runtime/run_report.h"
#include "hiltwin/tuning/tuning_report.h"

namespace hiltwin::app {

/// `tune`'s typed configuration (its flags parsed by cli/commands/cmd_tune.cpp).
struct TuneOptions {
  double controller_rate_hz = 1000.0;
  double tolerance_m = 1.0e-4;
  std::vector<double> candidates_hz = {1000.0, 2000.0, 4000.0, 8000.0, 16000.0};
  double validate_seconds = 5.0;
  double latency_seconds = 1.0;  ///< per candidate, real clock only
  runtime::ClockKind clock = runtime::ClockKind::kRealtime;
  /// Virtual clock only: costs given instead of measured, which makes the procedure exact.
  std::optional<double> inject_compute_us;
  std::optional<double> inject_overhead_us;
  std::optional<double> inject_latency_us;
  int priority = 80;
  std::vector<int> cpus;
  std::string input = "openloop";
  std::string config_path;
  std::string integrator = "rk4";
};

/// Checks the flags; throws CommandError(kUsage) naming the flag, the value and the fix.
void CheckTuneOptions(const TuneOptions& o);

/// Called before each step of the procedure: the fraction done (0..1) and what comes next.
using TuneProgress = std::function<void(double fraction_done, const std::string& what)>;

/// Runs the procedure. Throws CommandError for bad flags (exit 2) or a board that cannot be
/// opened (exit 5).
[[nodiscard]] analysis::TuneReport RunTune(const TuneOptions& o, const TuneProgress& progress);

}  // namespace hiltwin::app
