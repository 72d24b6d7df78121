#pragma once
/// Lifecycle of a twin or a controller: init -> ready -> run -> stopping -> stopped, with
/// pause, and error -> safe_stop for faults. Pure logic: events come from outside (the loop,
/// signal flags, commands, the QoS monitor), nothing here touches the OS, allocates or throws.
/// Illegal events are rejected with a result, never an exception. docs/lifecycle.md has the
/// diagram and the mapping of the seed ECS framework's commands.
///
/// What each state allows (RulesOf() returns the same table):
///
/// | state     | cycles released | model stepped | outputs      | QoS records | terminal |
/// |-----------|-----------------|---------------|--------------|-------------|----------|
/// | init      | no              | no            | safe (closed)| no          | no       |
/// | ready     | no              | no            | safe         | no          | no       |
/// | run       | yes             | yes           | live         | yes         | no       |
/// | paused    | yes (link kept) | no            | safe         | no          | no       |
/// | stopping  | no              | no            | safe         | no          | no       |
/// | stopped   | no              | no            | safe         | no          | yes      |
/// | error     | no              | no            | safe, now    | no          | no       |
/// | safe_stop | no              | no            | safe         | no          | yes      |
///
/// "Safe" outputs are the application's safe values: zero duty on the controller side; on the
/// twin side the encoder outputs held still (no pulses), which a controller reads as a robot
/// at rest. Only `run` writes model-driven outputs.
///
/// Transitions (anything else is rejected; "ignored" means accepted without a change, e.g. a
/// second Ctrl-C while already stopping):
///
///   init      --configured--> ready       --start--> run        --pause--> paused
///   paused    --start-->      run
///   init|ready|run|paused --stop_request--> stopping   (reason stop_requested)
///   run|paused --finish_reached--> stopping             (reason finished)
///   run|paused --peer_stopped-->   stopping             (reason peer_stopped)
///   run       --qos_abort-->  error                     (reason qos_abort)
///   init|ready|run|paused|stopping --io_fault|model_fault--> error
///   stopping  --drained-->    stopped     error --drained--> safe_stop
///   stopped|safe_stop --reset--> init
///   ignored: stop_request, finish_reached, peer_stopped, qos_abort in
///            stopping/stopped/error/safe_stop;
///            io_fault, model_fault in error/stopped/safe_stop.
///
/// The stop reason is the cause of the first transition out of init/ready/run/paused; a fault
/// that arrives while stopping still sends the machine to error (outputs must go safe) but is
/// kept apart as fault_while_stopping(), so the report names the original cause.
///
/// Seed ECS framework (FullStateMachine) commands: initialise = set up, then `configured`
/// (its initialising/initialised become init/ready); start = `start` (also resumes from
/// paused); stop = `stop_request`, then `drained`; pause = `pause`; a state function
/// returning < 0 = `io_fault`/`model_fault` (and `qos_abort`), then `drained` to safe_stop;
/// reset = `reset`, only from stopped/safe_stop (the seed also resets a running machine: here
/// stop first); quit = no event, the process exits when RulesOf(state).terminal.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <iterator>

namespace hiltwin::lifecycle {

enum class State : std::uint8_t {
  kInit,      ///< constructed; configuration, I/O and model being set up
  kReady,     ///< everything allocated and opened; waiting for start
  kRun,       ///< the loop releases cycles and steps the model
  kPaused,    ///< cycles still released (link kept alive), model frozen, outputs safe
  kStopping,  ///< a normal stop: outputs safe, logs being drained
  kStopped,   ///< normal end (terminal until reset)
  kError,     ///< a fault or a QoS abort: outputs go safe at once, logs being drained
  kSafeStop,  ///< end after a fault (terminal until reset)
};

enum class Event : std::uint8_t {
  kConfigured,     ///< set-up finished (I/O open, model initialised, buffers allocated)
  kStart,          ///< start or resume
  kPause,          ///< freeze the model, keep the loop and link alive
  kStopRequest,    ///< SIGINT/SIGTERM or a stop command
  kFinishReached,  ///< the planned duration has run
  kQosAbort,       ///< the QoS monitor under policy abort says stop
  kIoFault,        ///< the I/O backend failed (wrong FPGA image, broken link, bad frames)
  kModelFault,     ///< the model produced a non-finite state
  kDrained,        ///< safe outputs written and the log flushed
  kReset,          ///< back to init for another run
  kPeerStopped,    ///< the process on the other end of the link stopped cleanly (wire)
};

/// Why the run stopped; the strings are the run report's `stop_reason`.
enum class StopReason : std::uint8_t {
  kNone,           ///< "none": not stopped (yet)
  kFinished,       ///< "finished"
  kStopRequested,  ///< "stop_requested"
  kQosAbort,       ///< "qos_abort"
  kIoFault,        ///< "io_fault"
  kModelFault,     ///< "model_fault"
  kPeerStopped,    ///< "peer_stopped": the other process ended its run (finish, stop, abort)
};

enum class Outcome : std::uint8_t {
  kTransitioned,  ///< the state changed (from != to)
  kIgnored,       ///< legal but redundant; the state is unchanged
  kRejected,      ///< illegal in this state; the state is unchanged
};

/// The result of offering an event.
struct Transition {
  Outcome outcome = Outcome::kRejected;
  State from = State::kInit;
  State to = State::kInit;
};

/// What a state allows; see the table above.
struct StateRules {
  bool releases_cycles = false;  ///< the loop keeps its release grid and does I/O
  bool steps_model = false;      ///< the loop may call the model's step
  bool live_outputs = false;     ///< false: outputs must hold their safe values
  bool records_qos = false;      ///< cycles count towards the QoS verdict
  bool terminal = false;         ///< nothing happens until reset (the process may exit)
};

/// What `state` allows. A table lookup, inline: the loop asks once per cycle (RunSession).
[[nodiscard]] constexpr StateRules RulesOf(State state) noexcept {
  constexpr StateRules kRun{.releases_cycles = true,
                            .steps_model = true,
                            .live_outputs = true,
                            .records_qos = true,
                            .terminal = false};
  constexpr StateRules kPaused{.releases_cycles = true};
  constexpr StateRules kTerminal{.terminal = true};
  constexpr StateRules kNothing{};
  constexpr StateRules kTable[] = {
      kNothing,   // init
      kNothing,   // ready
      kRun,       // run
      kPaused,    // paused
      kNothing,   // stopping
      kTerminal,  // stopped
      kNothing,   // error
      kTerminal,  // safe_stop
  };
  static_assert(static_cast<std::size_t>(State::kSafeStop) + 1 == std::size(kTable));
  const auto index = static_cast<std::size_t>(state);
  return index < std::size(kTable) ? kTable[index] : kNothing;
}
/// The transition table as a pure function (from == to unless outcome is kTransitioned).
[[nodiscard]] Transition Next(State state, Event event) noexcept;
/// The stop reason an event stands for (kNone for events that do not stop the run).
[[nodiscard]] StopReason ReasonOf(Event event) noexcept;

[[nodiscard]] const char* ToString(State state) noexcept;
[[nodiscard]] const char* ToString(Event event) noexcept;
[[nodiscard]] const char* ToString(StopReason reason) noexcept;
[[nodiscard]] const char* ToString(Outcome outcome) noexcept;

/// The machine. Handle() is called from one thread at a time (the loop while it runs, the
/// main thread otherwise); state() may be read from any thread.
class Lifecycle {
 public:
  /// Offers an event; applies it when legal. Never throws, never allocates.
  Transition Handle(Event event) noexcept;

  [[nodiscard]] State state() const noexcept { return state_.load(std::memory_order_acquire); }
  [[nodiscard]] StateRules rules() const noexcept { return RulesOf(state()); }
  /// Cause of the first stop since construction or the last reset ("none" while running).
  [[nodiscard]] StopReason stop_reason() const noexcept { return stop_reason_; }
  /// A fault that arrived while already stopping (kNone if none).
  [[nodiscard]] StopReason fault_while_stopping() const noexcept { return late_fault_; }

 private:
  std::atomic<State> state_{State::kInit};
  StopReason stop_reason_ = StopReason::kNone;
  StopReason late_fault_ = StopReason::kNone;
};

}  // namespace hiltwin::lifecycle
