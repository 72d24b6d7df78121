#include "hiltwin/lifecycle/lifecycle.h"

namespace hiltwin::lifecycle {
namespace {

constexpr Transition To(State from, State to) noexcept {
  return Transition{.outcome = Outcome::kTransitioned, .from = from, .to = to};
}
constexpr Transition Ignore(State state) noexcept {
  return Transition{.outcome = Outcome::kIgnored, .from = state, .to = state};
}
constexpr Transition Reject(State state) noexcept {
  return Transition{.outcome = Outcome::kRejected, .from = state, .to = state};
}

// Already on the way out (or out): further stop causes change nothing.
constexpr bool Ending(State state) noexcept {
  return state == State::kStopping || state == State::kStopped || state == State::kError ||
         state == State::kSafeStop;
}

}  // namespace

Transition Next(State state, Event event) noexcept {
  switch (event) {
    case Event::kConfigured:
      return state == State::kInit ? To(state, State::kReady) : Reject(state);
    case Event::kStart:
      return (state == State::kReady || state == State::kPaused) ? To(state, State::kRun)
                                                                 : Reject(state);
    case Event::kPause:
      return state == State::kRun ? To(state, State::kPaused) : Reject(state);
    case Event::kStopRequest:
      if (Ending(state)) return Ignore(state);
      return To(state, State::kStopping);
    case Event::kPeerStopped:
      // The peer may run, and end, while this side still waits in ready for it to come up
      // (a peer that aborts in its first cycles): this side ends too, without a cycle.
      if (state == State::kReady) return To(state, State::kStopping);
      [[fallthrough]];
    case Event::kFinishReached:
      // Paused cycles are still released, so the planned releases can run out while paused.
      if (state == State::kRun || state == State::kPaused) return To(state, State::kStopping);
      return Ending(state) ? Ignore(state) : Reject(state);
    case Event::kQosAbort:
      if (state == State::kRun) return To(state, State::kError);
      return Ending(state) ? Ignore(state) : Reject(state);
    case Event::kIoFault:
    case Event::kModelFault:
      if (state == State::kError || state == State::kStopped || state == State::kSafeStop) {
        return Ignore(state);
      }
      return To(state, State::kError);
    case Event::kDrained:
      if (state == State::kStopping) return To(state, State::kStopped);
      if (state == State::kError) return To(state, State::kSafeStop);
      return Reject(state);
    case Event::kReset:
      return (state == State::kStopped || state == State::kSafeStop) ? To(state, State::kInit)
                                                                     : Reject(state);
  }
  return Reject(state);
}

StopReason ReasonOf(Event event) noexcept {
  switch (event) {
    case Event::kStopRequest:
      return StopReason::kStopRequested;
    case Event::kFinishReached:
      return StopReason::kFinished;
    case Event::kPeerStopped:
      return StopReason::kPeerStopped;
    case Event::kQosAbort:
      return StopReason::kQosAbort;
    case Event::kIoFault:
      return StopReason::kIoFault;
    case Event::kModelFault:
      return StopReason::kModelFault;
    case Event::kConfigured:
    case Event::kStart:
    case Event::kPause:
    case Event::kDrained:
    case Event::kReset:
      return StopReason::kNone;
  }
  return StopReason::kNone;
}

Transition Lifecycle::Handle(Event event) noexcept {
  const State current = state_.load(std::memory_order_relaxed);
  const Transition result = Next(current, event);
  if (result.outcome != Outcome::kTransitioned) return result;
  if (event == Event::kReset) {
    stop_reason_ = StopReason::kNone;
    late_fault_ = StopReason::kNone;
  } else if (const StopReason reason = ReasonOf(event); reason != StopReason::kNone) {
    if (stop_reason_ == StopReason::kNone) {
      stop_reason_ = reason;
    } else if (late_fault_ == StopReason::kNone) {
      late_fault_ = reason;  // only faults can move a stopping machine on (to error)
    }
  }
  state_.store(result.to, std::memory_order_release);
  return result;
}

const char* ToString(State state) noexcept {
  switch (state) {
    case State::kInit:
      return "init";
    case State::kReady:
      return "ready";
    case State::kRun:
      return "run";
    case State::kPaused:
      return "paused";
    case State::kStopping:
      return "stopping";
    case State::kStopped:
      return "stopped";
    case State::kError:
      return "error";
    case State::kSafeStop:
      return "safe_stop";
  }
  return "unknown";
}

const char* ToString(Event event) noexcept {
  switch (event) {
    case Event::kConfigured:
      return "configured";
    case Event::kStart:
      return "start";
    case Event::kPause:
      return "pause";
    case Event::kStopRequest:
      return "stop_request";
    case Event::kFinishReached:
      return "finish_reached";
    case Event::kQosAbort:
      return "qos_abort";
    case Event::kIoFault:
      return "io_fault";
    case Event::kModelFault:
      return "model_fault";
    case Event::kDrained:
      return "drained";
    case Event::kReset:
      return "reset";
    case Event::kPeerStopped:
      return "peer_stopped";
  }
  return "unknown";
}

const char* ToString(StopReason reason) noexcept {
  switch (reason) {
    case StopReason::kNone:
      return "none";
    case StopReason::kFinished:
      return "finished";
    case StopReason::kStopRequested:
      return "stop_requested";
    case StopReason::kQosAbort:
      return "qos_abort";
    case StopReason::kIoFault:
      return "io_fault";
    case StopReason::kModelFault:
      return "model_fault";
    case StopReason::kPeerStopped:
      return "peer_stopped";
  }
  return "unknown";
}

const char* ToString(Outcome outcome) noexcept {
  switch (outcome) {
    case Outcome::kTransitioned:
      return "transitioned";
    case Outcome::kIgnored:
      return "ignored";
    case Outcome::kRejected:
      return "rejected";
  }
  return "unknown";
}

}  // namespace hiltwin::lifecycle
