#include "telemetry_publisher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace hiltwin::runtime {
namespace {

/// The ring holds two ticks of cycles at least (the thread may be a tick late), as a power of
/// two between 1 Ki and 1 Mi values.
std::size_t LatencyRingCapacity(double loop_rate_hz, double telemetry_rate_hz) {
  const double per_tick = loop_rate_hz / telemetry_rate_hz;
  std::size_t capacity = 1024;
  while (static_cast<double>(capacity) < 2.0 * per_tick && capacity < (std::size_t{1} << 20)) {
    capacity *= 2;
  }
  return capacity;
}

/// The window is the last second of cycles (at least one, at most 1 Mi).
std::size_t WindowSize(double loop_rate_hz) {
  return static_cast<std::size_t>(std::clamp(std::ceil(loop_rate_hz), 1.0, 1048576.0));
}

}  // namespace

TelemetryPublisher::TelemetryPublisher(const TelemetryConfig& config, const TelemetryShape& shape,
                                       TelemetryIdentity identity, TelemetrySources sources,
                                       std::function<bool(SessionCommand)> post)
    : sinks_(config.sinks),
      telemetry_rate_hz_(config.rate_hz),
      identity_(std::move(identity)),
      shape_(shape),
      sources_(sources),
      post_(std::move(post)),
      latencies_(LatencyRingCapacity(identity_.rate_hz, config.rate_hz)),
      window_ns_(WindowSize(identity_.rate_hz)),
      scratch_ns_(window_ns_.size()) {
  if (!(config.rate_hz > 0.0 && config.rate_hz <= 1000.0)) {
    throw std::invalid_argument("telemetry rate must be above 0 and at most 1000 Hz");
  }
  if (shape_.joint_names.size() > kMaxTelemetryJoints) {
    throw std::invalid_argument("a task publishes at most 4 joints");
  }
  port_ = [this](RemoteCommand command, std::string& why) { return Accept(command, why); };
  for (const auto& sink : sinks_) sink->Open(shape_, identity_.ns);
}

TelemetryPublisher::~TelemetryPublisher() { Stop(); }

void TelemetryPublisher::Start(const std::vector<int>& cpus) {
  thread_.emplace(kernel_glue::ThreadSpec{"hiltwin-telem", cpus}, [this] { ThreadMain(); });
}

void TelemetryPublisher::Stop() {
  if (!thread_) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_->Join();
  thread_.reset();
  PublishToSinks(BuildRecord(true));
}

void TelemetryPublisher::ThreadMain() {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / telemetry_rate_hz_));
  auto next = std::chrono::steady_clock::now();
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    PublishToSinks(BuildRecord(false));
    for (const auto& sink : sinks_) sink->PollCommands(port_);
    lock.lock();
    // Absolute ticks, like the loop's releases; a late tick is not made up for.
    next = std::max(next + period, std::chrono::steady_clock::now());
    wake_.wait_until(lock, next, [this] { return stopping_; });
  }
}

void TelemetryPublisher::PublishToSinks(const TelemetryRecord& record) {
  for (const auto& sink : sinks_) sink->Publish(record);
}

void TelemetryPublisher::DrainLatencies() noexcept {
  std::int64_t value = 0;
  while (latencies_.TryPop(value)) {
    window_ns_[window_next_] = value;
    window_next_ = (window_next_ + 1) % window_ns_.size();
    window_filled_ = std::min(window_filled_ + 1, window_ns_.size());
  }
}

TelemetryRecord TelemetryPublisher::BuildRecord(bool final) {
  mailbox_.Update();
  DrainLatencies();
  const LoopSnapshot& snapshot = mailbox_.Front();
  const qos::LiveQos q = sources_.monitor.Live();
  TelemetryRecord r;
  r.ns = identity_.ns;
  r.role = shape_.role;
  r.rate_hz = identity_.rate_hz;
  r.time_s = snapshot.task_time_s;
  r.cycle = sources_.executive.live().cycles_run.load(std::memory_order_relaxed);
  r.cycles_planned = identity_.cycles_planned;
  r.state = sources_.lifecycle.state();
  r.final = final;
  r.deadline_misses = q.deadline_misses;
  if (window_filled_ > 0) {
    std::copy_n(window_ns_.begin(), window_filled_, scratch_ns_.begin());
    const auto end = scratch_ns_.begin() + static_cast<std::ptrdiff_t>(window_filled_);
    // Nearest rank, as the run report's percentiles.
    const auto rank =
        static_cast<std::ptrdiff_t>(std::ceil(0.99 * static_cast<double>(window_filled_)) - 1.0);
    std::nth_element(scratch_ns_.begin(), scratch_ns_.begin() + rank, end);
    r.latency_p99_us = static_cast<double>(scratch_ns_[static_cast<std::size_t>(rank)]) * 1e-3;
    r.latency_max_us = static_cast<double>(*std::max_element(scratch_ns_.begin(), end)) * 1e-3;
  }
  r.latency_samples = window_filled_;
  if (q.distance_to_failure != qos::kNeverFails) r.distance_to_violation = q.distance_to_failure;
  r.verdict_so_far = q.verdict;
  r.task = snapshot.task;
  r.joint_names = shape_.joint_names;
  return r;
}

bool TelemetryPublisher::Accept(RemoteCommand command, std::string& why) const {
  std::optional<SessionCommand> session_command;
  switch (command) {
    case RemoteCommand::kStart:
      session_command = SessionCommand::kResume;
      break;
    case RemoteCommand::kStop:
    case RemoteCommand::kQuit:  // a stopped hiltwin task exits: QUIT is STOP here
      session_command = SessionCommand::kStop;
      break;
    case RemoteCommand::kPause:
      session_command = SessionCommand::kPause;
      break;
    case RemoteCommand::kInitialise:
      why = "a hiltwin task initialises once, before it starts; this one is running";
      return false;
    case RemoteCommand::kReset:
      why = "RESET applies to a stopped task, and a stopped hiltwin task exits: start a new run";
      return false;
  }
  if (!session_command) {
    why = "unknown command";
    return false;
  }
  if (!post_(*session_command)) {
    why = "the loop has not yet taken the commands before it (queue full); send it again";
    return false;
  }
  return true;
}

}  // namespace hiltwin::runtime
