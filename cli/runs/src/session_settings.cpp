// The shared settings' checks (session_settings.h): on typed values, whoever made them (the
// command line, once, or `tune` for each of its runs).
#include "hiltwin/runs/session_settings.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hiltwin/runs/command.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/scheduler/executive.h"

namespace hiltwin::app {

void ValidateSessionSettings(const SessionSettings& s) {
  try {
    scheduler::ValidateRateHz(s.rate_hz);
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string("--rate: ") + e.what());
  }
  if (!std::isfinite(s.duration_s) || s.duration_s <= 0.0 || s.duration_s > 7 * 86400.0) {
    ThrowUsage("--duration " + Num(s.duration_s) +
               ": must be a positive number of seconds, at most 604800 (7 days)");
  }
  if (s.deadline_ns < 0 || s.deadline_ns > kernel_glue::PeriodNsFromRateHz(s.rate_hz)) {
    ThrowUsage("--deadline-us: must be between 0 (= the period) and the period (" +
               Num(1e6 / s.rate_hz) + " us)");
  }
  if (s.log_decimation == 0) ThrowUsage("--log-decimation: must be at least 1");
  if (s.priority < 0 || s.priority > 99) ThrowUsage("--priority: 0 (no SCHED_FIFO) .. 99");
  if (!std::isfinite(s.wait_peer_s) || s.wait_peer_s < 0.0 || s.wait_peer_s > 86400.0) {
    ThrowUsage("--wait-peer " + Num(s.wait_peer_s) + ": must be 0 .. 86400 seconds");
  }
}

}  // namespace hiltwin::app
