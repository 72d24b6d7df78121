#pragma once
/// Live telemetry out of a running session, and commands into it (docs/architecture.md, "Where
/// users outgrow one machine"). The loop writes a LoopSnapshot into a latest-value mailbox every
/// cycle (latest_value.h: never blocks, never allocates) and pushes the cycle's wake-up latency
/// into a ring; a non-RT thread (`hiltwin-telem`, SCHED_OTHER) reads both at
/// TelemetryConfig::rate_hz, builds one TelemetryRecord, and hands it to every sink (DDS, UDP, the
/// web page). Commands that arrive through a sink go through a lock-free queue to the loop, which
/// offers them to the lifecycle after its current cycle; the loop never waits on the network.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/qos/monitor.h"

namespace hiltwin::runtime {

/// Most joints a task can publish (the board has four channels).
inline constexpr std::size_t kMaxTelemetryJoints = 4;

/// What a task publishes besides timing, filled on the loop thread (RunTask::FillTelemetry):
/// fixed size, trivially copyable, so the mailbox copies it without allocating.
struct TaskTelemetry {
  bool has_pose = false;
  double x_m = 0.0;  ///< planar pose, world frame
  double y_m = 0.0;
  double theta_rad = 0.0;  ///< heading, unwrapped
  std::uint8_t joint_count = 0;
  std::array<double, kMaxTelemetryJoints> joint_position_rad{};  ///< wheel angles
  std::array<double, kMaxTelemetryJoints> joint_position_m{};    ///< wheel travel (r·angle)
  /// What a closed-loop controller tells each joint to be at, as travel (m), in the joints'
  /// order; without one (a twin, an open loop) has_setpoint stays false and the record has no
  /// setpoint. The page draws a robot driven by it beside the real one.
  bool has_setpoint = false;
  std::array<double, kMaxTelemetryJoints> joint_setpoint_m{};
};

/// What a task's telemetry looks like, fixed for a run (RunTask::TelemetryShapeOf).
struct TelemetryShape {
  std::string role = "task";  ///< "twin" or "controller": for the monitor
  bool has_pose = false;
  std::vector<std::string> joint_names;  ///< ROS joint names, one per joint (≤ 4)
  /// Set by the session, not the task: on the virtual clock the DDS sink stamps with the task's
  /// time and publishes it as ROS 2's /clock (but the controller of a lockstep pair, whose time
  /// base is its twin's); on the real clock it stamps with system time.
  bool virtual_clock = false;
  bool lockstep = false;
};

/// The loop's part of a telemetry record: written every cycle, read at the telemetry rate.
struct LoopSnapshot {
  std::uint64_t cycle = 0;   ///< release index of the last completed cycle
  double task_time_s = 0.0;  ///< the task's time after its last step (the log's time_s)
  TaskTelemetry task;
};

/// One telemetry sample, built on the telemetry thread: every output (DDS, UDP, web, monitor)
/// derives from this record.
struct TelemetryRecord {
  // Who.
  std::string ns;    ///< ROS namespace without leading slash, e.g. "bench1/twin"
  std::string role;  ///< TelemetryShape::role
  double rate_hz = 0.0;
  // When.
  double time_s = 0.0;               ///< the task's time (the CSV log's first column)
  std::uint64_t cycle = 0;           ///< cycles run so far
  std::uint64_t cycles_planned = 0;  ///< 0: until stopped
  lifecycle::State state = lifecycle::State::kInit;
  bool final = false;  ///< the last record of the run (published after the loop)
  // Timing, as the QoS monitor and the loop saw it.
  std::uint64_t deadline_misses = 0;  ///< every miss so far, grace period included
  /// Wake-up latency over the last second of cycles (or fewer at the start); 0 before the
  /// first cycle.
  double latency_p99_us = 0.0;
  double latency_max_us = 0.0;
  std::uint64_t latency_samples = 0;  ///< cycles the two figures above were taken over
  /// Consecutive misses from now that would violate the nearest rule; nullopt: no rule can
  /// fail (qos::kNeverFails).
  std::optional<std::uint32_t> distance_to_violation;
  qos::Verdict verdict_so_far = qos::Verdict::kPass;
  // The task's values, named by the shape.
  TaskTelemetry task;
  std::vector<std::string> joint_names;
};

/// The seed ECS framework's command codes (thesis; `rt/<ns>/command`, std_msgs Int32).
enum class RemoteCommand : std::int32_t {
  kInitialise = 1,
  kStart = 2,
  kStop = 3,
  kReset = 4,
  kPause = 5,
  kQuit = 6,
};
/// The code's name ("INITIALISE", ...); "unknown" for other values.
[[nodiscard]] const char* ToString(RemoteCommand command) noexcept;
/// A received code as a command; nullopt for codes outside 1..6.
[[nodiscard]] std::optional<RemoteCommand> RemoteCommandOf(std::int32_t code) noexcept;

/// Where a sink hands a received command: true when the session took it (queued for the
/// loop), false with `why` filled when it does not apply (e.g. RESET while running).
using CommandPort = std::function<bool(RemoteCommand command, std::string& why)>;

/// One way out (DDS, UDP, web). Every call comes from the telemetry thread except the
/// constructor (the command, before the run) and Open (RunSession's constructor, on the
/// control thread). A sink acquires what can fail for a user's reason (a port in use, a bad
/// address) in its factory, so the command exits 2 before anything starts.
class TelemetrySink {
 public:
  virtual ~TelemetrySink() = default;
  /// Completes the set-up for a task of this shape and namespace; may throw
  /// std::runtime_error (the session then fails to build: exit 2 with the message).
  virtual void Open(const TelemetryShape& shape, const std::string& ns) = 0;
  /// Sends one record; must not block for long (the telemetry thread's budget is its period).
  virtual void Publish(const TelemetryRecord& record) noexcept = 0;
  /// Hands commands received since the last call to `port`. Sinks without an inbound side
  /// keep the default.
  virtual void PollCommands(const CommandPort& port) noexcept { static_cast<void>(port); }
  /// What the user reads in the start-up lines, e.g. "DDS domain 0 rt/twin/{pose,joint_states,
  /// timing,command}".
  [[nodiscard]] virtual std::string Describe() const = 0;
};

/// SessionConfig::telemetry: no sinks, no telemetry thread and no per-cycle cost.
struct TelemetryConfig {
  double rate_hz = 50.0;  ///< records per second to every sink (0 < rate ≤ 1000)
  std::string ns;         ///< namespace of this task's topics and records
  std::vector<std::shared_ptr<TelemetrySink>> sinks;
};

}  // namespace hiltwin::runtime
