#pragma once
/// The typed configuration every session shares (`run`'s twin, `ecs`'s controller, `tune`'s
/// runs): what the shared flags mean once the command line has parsed them (cli/session_flags.h,
/// the one place their text is read). Everything below the command layer takes these values,
/// never the flags' text, so a run started a hundred times by `tune` parses nothing.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/scheduler/overrun_policy.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::app {

/// --wait-peer's default; another value (but 0) is refused off a wire.
constexpr double kDefaultWaitPeerS = 30.0;

struct SessionSettings {
  double rate_hz = 4000.0;
  double duration_s = 10.0;
  io::BackendSpec io;            ///< --io (default mock)
  std::string io_text = "mock";  ///< --io as given: for messages, the start line and the report
  std::optional<io::Image> board_image;  ///< fault injection: the emulated board's image
  runtime::ClockKind clock = runtime::ClockKind::kRealtime;
  scheduler::OverrunPolicy overrun_policy = scheduler::OverrunPolicy::kCatchUp;
  qos::ViolationPolicy on_violation = qos::ViolationPolicy::kFlag;
  /// Every rule the monitor checks, in the report's order (miss ratio, (m,k) with the
  /// documented default when --qos is not given, windows, consecutive misses).
  std::vector<qos::RuleSpec> qos_rules;
  std::uint64_t grace_cycles = 0;
  /// 0: the period; at most the period. Negative: a --deadline-us no run can have (refused by
  /// ValidateSessionSettings, naming the flag).
  kernel_glue::TimeNs deadline_ns = 0;
  std::vector<runtime::OverrunInjection> overrun_injections;
  std::string log_path;
  std::uint32_t log_decimation = 1;
  std::string timing_log_path;  ///< every cycle's time stamps, for `hiltwin trace --analyze`
  std::string report_path;
  int priority = 80;  ///< SCHED_FIFO priority of the loop (0: none)
  std::vector<int> cpus;
  bool progress = true;  ///< a progress line when stderr is a terminal
  double wait_peer_s = kDefaultWaitPeerS;
  /// --telemetry, --namespace (empty: the role's default), --web, --telemetry-rate: kept as
  /// given, because telemetry::MakeTelemetryConfig parses them as it opens the sinks, and a
  /// sink (a bound port, a DDS participant) belongs to one session, not to the command line.
  telemetry::TelemetryOptions telemetry;
};

/// The numbers' checks (rate, duration, deadline, log decimation, priority, wait); throws
/// CommandError(kUsage) naming the flag and the fix.
void ValidateSessionSettings(const SessionSettings& s);

}  // namespace hiltwin::app
