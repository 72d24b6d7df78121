#pragma once
/// `hiltwin monitor`'s side of DDS: finds every hiltwin task on a domain (any participant that
/// publishes an `rt/<ns>/timing` topic, found through DDS's built-in publication topic, as
/// `ros2 topic list` does), reads their timing records, and sends commands to one of them.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/runtime/telemetry.h"

namespace hiltwin::telemetry {

/// The latest timing record of one task on the domain.
struct MonitorEntry {
  std::string ns;
  std::string role;
  double rate_hz = 0.0;
  double time_s = 0.0;
  std::uint64_t cycle = 0;
  std::uint64_t cycles_planned = 0;
  std::uint64_t deadline_misses = 0;
  double latency_p99_us = 0.0;
  std::optional<std::uint32_t> distance_to_violation;
  std::string verdict;  ///< "PASS", "FLAGGED", "ABORTED"
  std::string state;    ///< lifecycle state name
  bool final = false;   ///< the task has published its last record
  double age_s = 0.0;   ///< since this entry's last record arrived (monitor's monotonic clock)
};

class DdsMonitor {
 public:
  /// Joins `domain` as a participant; throws std::invalid_argument (domain above 232) or
  /// std::runtime_error (Cyclone refused: the message says how to fix it).
  explicit DdsMonitor(std::uint32_t domain);
  ~DdsMonitor();
  DdsMonitor(const DdsMonitor&) = delete;
  DdsMonitor& operator=(const DdsMonitor&) = delete;

  /// Discovers new tasks and takes every record that arrived; returns every task seen so far,
  /// sorted by namespace.
  [[nodiscard]] std::vector<MonitorEntry> Poll();

  /// Every namespace discovered so far (a task may be listed before its first record).
  [[nodiscard]] std::vector<std::string> Namespaces() const;

  /// Sends `command` to rt/<ns>/command once a reader there is matched, waiting up to
  /// `timeout_s`, then waits up to 2 s for the reader's acknowledgement. Returns "" when
  /// delivered to a task that takes commands, else why not (for the message; exit 2): no
  /// reader, no acknowledgement, or a task started without --accept-commands (its reader's
  /// user data says so; the command is still sent, so the task reports the attempt).
  [[nodiscard]] std::string SendCommand(const std::string& ns, runtime::RemoteCommand command,
                                        double timeout_s);

 private:
  struct State;
  State* state_;
};

}  // namespace hiltwin::telemetry
