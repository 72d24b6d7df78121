#pragma once
// The telemetry thread of a RunSession (telemetry.h): at the configured rate it takes the
// loop's latest snapshot and the wake-up latencies since its last tick, reads the QoS
// monitor's and the executive's live figures, builds one TelemetryRecord and hands it to every
// sink, then gives the sinks the chance to pass on commands they received. It runs SCHED_OTHER
// on the helper CPUs; nothing it does can delay the loop, which only ever writes the mailbox
// and pushes into the latency ring.

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "cycle_runner.h"
#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/lockfree/latest_value.h"
#include "hiltwin/lockfree/spsc_ring.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/runtime/session_command.h"
#include "hiltwin/runtime/telemetry.h"
#include "hiltwin/scheduler/executive.h"

namespace hiltwin::runtime {

/// What the publisher reads besides the mailbox; none owned, all outlive it.
struct TelemetrySources {
  const qos::QosMonitor& monitor;
  const scheduler::Executive& executive;
  const lifecycle::Lifecycle& lifecycle;
};

/// How the publisher identifies the task in every record.
struct TelemetryIdentity {
  std::string ns;
  double rate_hz = 0.0;
  std::uint64_t cycles_planned = 0;
};

class TelemetryPublisher {
 public:
  /// Opens every sink for this task (std::runtime_error from a sink propagates) and allocates
  /// the mailbox, the latency ring and the latency window. `post` queues a command for the
  /// loop (false: the queue was full).
  TelemetryPublisher(const TelemetryConfig& config, const TelemetryShape& shape,
                     TelemetryIdentity identity, TelemetrySources sources,
                     std::function<bool(SessionCommand)> post);
  ~TelemetryPublisher();
  TelemetryPublisher(const TelemetryPublisher&) = delete;
  TelemetryPublisher& operator=(const TelemetryPublisher&) = delete;

  /// Where the loop leaves its telemetry.
  [[nodiscard]] TelemetryTaps taps() noexcept { return {&mailbox_, &latencies_}; }

  /// Starts the thread on `cpus` (empty: anywhere).
  void Start(const std::vector<int>& cpus);
  /// Stops the thread (within one tick), then publishes the final record (final = true) with
  /// the run's last state and verdict. Safe to call when never started.
  void Stop();

  /// Builds a record from what the loop has left so far: the thread's work, public for tests.
  [[nodiscard]] TelemetryRecord BuildRecord(bool final);
  /// What the sinks' commands do: maps a remote command onto the session, or says why not.
  bool Accept(RemoteCommand command, std::string& why) const;

 private:
  void ThreadMain();
  void PublishToSinks(const TelemetryRecord& record);
  void DrainLatencies() noexcept;

  std::vector<std::shared_ptr<TelemetrySink>> sinks_;
  double telemetry_rate_hz_;
  TelemetryIdentity identity_;
  TelemetryShape shape_;
  TelemetrySources sources_;
  std::function<bool(SessionCommand)> post_;
  CommandPort port_;

  lockfree::LatestValue<LoopSnapshot> mailbox_;
  lockfree::SpscQueue<std::int64_t> latencies_;
  std::vector<std::int64_t> window_ns_;  ///< the last second of latencies, a ring
  std::size_t window_next_ = 0;
  std::size_t window_filled_ = 0;
  std::vector<std::int64_t> scratch_ns_;  ///< for the percentile (nth_element reorders)

  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::optional<kernel_glue::NamedThread> thread_;
};

}  // namespace hiltwin::runtime
