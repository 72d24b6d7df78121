// Every (state, event) pair of the lifecycle against a table written out independently here,
// the stop reasons, the per-state rules, and the seed ECS framework's command sequences.

#include "hiltwin/lifecycle/lifecycle.h"

#include <gtest/gtest.h>

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace hiltwin::lifecycle {
namespace {

constexpr std::array kStates = {State::kInit,     State::kReady,   State::kRun,   State::kPaused,
                                State::kStopping, State::kStopped, State::kError, State::kSafeStop};
constexpr std::array kEvents = {Event::kConfigured,  Event::kStart,         Event::kPause,
                                Event::kStopRequest, Event::kFinishReached, Event::kQosAbort,
                                Event::kIoFault,     Event::kModelFault,    Event::kDrained,
                                Event::kReset,       Event::kPeerStopped};

using S = State;
using E = Event;

// The legal transitions, spelled out one by one (docs/lifecycle.md, lifecycle.h).
const std::map<std::pair<State, Event>, State>& Legal() {
  static const std::map<std::pair<State, Event>, State> table = {
      {{S::kInit, E::kConfigured}, S::kReady},
      {{S::kInit, E::kStopRequest}, S::kStopping},
      {{S::kInit, E::kIoFault}, S::kError},
      {{S::kInit, E::kModelFault}, S::kError},
      {{S::kReady, E::kStart}, S::kRun},
      {{S::kReady, E::kStopRequest}, S::kStopping},
      {{S::kReady, E::kPeerStopped}, S::kStopping},  // the peer ran and ended first
      {{S::kReady, E::kIoFault}, S::kError},
      {{S::kReady, E::kModelFault}, S::kError},
      {{S::kRun, E::kPause}, S::kPaused},
      {{S::kRun, E::kStopRequest}, S::kStopping},
      {{S::kRun, E::kFinishReached}, S::kStopping},
      {{S::kRun, E::kPeerStopped}, S::kStopping},
      {{S::kRun, E::kQosAbort}, S::kError},
      {{S::kRun, E::kIoFault}, S::kError},
      {{S::kRun, E::kModelFault}, S::kError},
      {{S::kPaused, E::kStart}, S::kRun},
      {{S::kPaused, E::kStopRequest}, S::kStopping},
      {{S::kPaused, E::kFinishReached}, S::kStopping},  // the planned releases ran out
      {{S::kPaused, E::kPeerStopped}, S::kStopping},
      {{S::kPaused, E::kIoFault}, S::kError},
      {{S::kPaused, E::kModelFault}, S::kError},
      {{S::kStopping, E::kDrained}, S::kStopped},
      {{S::kStopping, E::kIoFault}, S::kError},
      {{S::kStopping, E::kModelFault}, S::kError},
      {{S::kError, E::kDrained}, S::kSafeStop},
      {{S::kStopped, E::kReset}, S::kInit},
      {{S::kSafeStop, E::kReset}, S::kInit},
  };
  return table;
}

// Redundant stop causes once the run is already ending: accepted, no change.
bool IsIgnored(State s, Event e) {
  const bool ending = s == S::kStopping || s == S::kStopped || s == S::kError || s == S::kSafeStop;
  if (e == E::kStopRequest || e == E::kFinishReached || e == E::kQosAbort ||
      e == E::kPeerStopped) {
    return ending;
  }
  if (e == E::kIoFault || e == E::kModelFault) {
    return s == S::kError || s == S::kStopped || s == S::kSafeStop;
  }
  return false;
}

// Drives a fresh machine into `target` along the shortest legal path.
void DriveTo(Lifecycle& machine, State target) {
  static const std::map<State, std::vector<Event>> paths = {
      {S::kInit, {}},
      {S::kReady, {E::kConfigured}},
      {S::kRun, {E::kConfigured, E::kStart}},
      {S::kPaused, {E::kConfigured, E::kStart, E::kPause}},
      {S::kStopping, {E::kConfigured, E::kStart, E::kStopRequest}},
      {S::kStopped, {E::kConfigured, E::kStart, E::kStopRequest, E::kDrained}},
      {S::kError, {E::kConfigured, E::kStart, E::kIoFault}},
      {S::kSafeStop, {E::kConfigured, E::kStart, E::kIoFault, E::kDrained}},
  };
  for (Event e : paths.at(target)) {
    EXPECT_EQ(machine.Handle(e).outcome, Outcome::kTransitioned);
  }
  EXPECT_EQ(machine.state(), target);
}

TEST(Lifecycle, EveryStateEventPairMatchesTheTable) {
  std::size_t transitions = 0;
  std::size_t ignored = 0;
  std::size_t rejected = 0;
  for (State s : kStates) {
    for (Event e : kEvents) {
      SCOPED_TRACE(std::string(ToString(s)) + " + " + ToString(e));
      Lifecycle machine;
      DriveTo(machine, s);
      const Transition result = machine.Handle(e);
      EXPECT_EQ(result.from, s);
      const auto legal = Legal().find({s, e});
      if (legal != Legal().end()) {
        EXPECT_EQ(result.outcome, Outcome::kTransitioned);
        EXPECT_EQ(result.to, legal->second);
        EXPECT_EQ(machine.state(), legal->second);
        ++transitions;
      } else if (IsIgnored(s, e)) {
        EXPECT_EQ(result.outcome, Outcome::kIgnored);
        EXPECT_EQ(result.to, s);
        EXPECT_EQ(machine.state(), s);
        ++ignored;
      } else {
        EXPECT_EQ(result.outcome, Outcome::kRejected);
        EXPECT_EQ(result.to, s);
        EXPECT_EQ(machine.state(), s);
        ++rejected;
      }
      const Transition pure = Next(s, e);
      EXPECT_EQ(pure.outcome, result.outcome);
      EXPECT_EQ(pure.to, result.to);
    }
  }
  EXPECT_EQ(transitions, Legal().size());
  EXPECT_EQ(transitions + ignored + rejected, kStates.size() * kEvents.size());
  EXPECT_EQ(ignored, 22U);  // 4 stop causes x 4 ending states + 2 faults x 3
}

TEST(Lifecycle, StopReasonIsTheFirstCause) {
  struct Case {
    std::vector<Event> events;
    StopReason reason;
    State end;
  };
  const std::vector<Case> cases = {
      {{E::kConfigured, E::kStart, E::kFinishReached, E::kDrained},
       StopReason::kFinished,
       S::kStopped},
      {{E::kConfigured, E::kStart, E::kStopRequest, E::kDrained},
       StopReason::kStopRequested,
       S::kStopped},
      {{E::kConfigured, E::kStart, E::kPeerStopped, E::kDrained},
       StopReason::kPeerStopped,
       S::kStopped},
      {{E::kConfigured, E::kStart, E::kQosAbort, E::kDrained}, StopReason::kQosAbort, S::kSafeStop},
      {{E::kConfigured, E::kStart, E::kIoFault, E::kDrained}, StopReason::kIoFault, S::kSafeStop},
      {{E::kConfigured, E::kStart, E::kModelFault, E::kDrained},
       StopReason::kModelFault,
       S::kSafeStop},
      {{E::kIoFault}, StopReason::kIoFault, S::kError},  // e.g. wrong FPGA image at set-up
      {{E::kStopRequest, E::kDrained}, StopReason::kStopRequested, S::kStopped},
      {{E::kConfigured, E::kStart, E::kPause, E::kStopRequest},
       StopReason::kStopRequested,
       S::kStopping},
      // A second signal or a late finish changes nothing.
      {{E::kConfigured, E::kStart, E::kStopRequest, E::kStopRequest, E::kFinishReached,
        E::kQosAbort},
       StopReason::kStopRequested,
       S::kStopping},
      {{E::kConfigured, E::kStart, E::kQosAbort, E::kIoFault}, StopReason::kQosAbort, S::kError},
  };
  for (const Case& c : cases) {
    Lifecycle machine;
    for (Event e : c.events) (void)machine.Handle(e);
    EXPECT_EQ(machine.stop_reason(), c.reason) << ToString(c.reason);
    EXPECT_EQ(machine.state(), c.end) << ToString(c.end);
    EXPECT_EQ(machine.fault_while_stopping(), StopReason::kNone);
  }
}

TEST(Lifecycle, AFaultWhileStoppingGoesSafeButKeepsTheOriginalReason) {
  Lifecycle machine;
  DriveTo(machine, S::kRun);
  EXPECT_EQ(machine.Handle(E::kFinishReached).to, S::kStopping);
  EXPECT_EQ(machine.Handle(E::kIoFault).to, S::kError);
  EXPECT_EQ(machine.stop_reason(), StopReason::kFinished);
  EXPECT_EQ(machine.fault_while_stopping(), StopReason::kIoFault);
  EXPECT_EQ(machine.Handle(E::kDrained).to, S::kSafeStop);
  EXPECT_FALSE(machine.rules().live_outputs);
}

TEST(Lifecycle, ResetClearsTheReasonsForANewRun) {
  Lifecycle machine;
  DriveTo(machine, S::kSafeStop);
  EXPECT_EQ(machine.stop_reason(), StopReason::kIoFault);
  EXPECT_EQ(machine.Handle(E::kReset).to, S::kInit);
  EXPECT_EQ(machine.stop_reason(), StopReason::kNone);
  EXPECT_EQ(machine.fault_while_stopping(), StopReason::kNone);
  for (Event e : {E::kConfigured, E::kStart, E::kFinishReached, E::kDrained}) {
    ASSERT_EQ(machine.Handle(e).outcome, Outcome::kTransitioned);
  }
  EXPECT_EQ(machine.stop_reason(), StopReason::kFinished);
}

TEST(Lifecycle, WhatEachStateAllows) {
  // Only run steps the model, writes live outputs and feeds QoS; paused keeps the loop.
  for (State s : kStates) {
    const StateRules rules = RulesOf(s);
    SCOPED_TRACE(ToString(s));
    EXPECT_EQ(rules.steps_model, s == S::kRun);
    EXPECT_EQ(rules.live_outputs, s == S::kRun);
    EXPECT_EQ(rules.records_qos, s == S::kRun);
    EXPECT_EQ(rules.releases_cycles, s == S::kRun || s == S::kPaused);
    EXPECT_EQ(rules.terminal, s == S::kStopped || s == S::kSafeStop);
  }
}

TEST(Lifecycle, Strings) {
  const std::vector<std::pair<StopReason, std::string>> reasons = {
      {StopReason::kNone, "none"},
      {StopReason::kFinished, "finished"},
      {StopReason::kStopRequested, "stop_requested"},
      {StopReason::kQosAbort, "qos_abort"},
      {StopReason::kIoFault, "io_fault"},
      {StopReason::kModelFault, "model_fault"},
      {StopReason::kPeerStopped, "peer_stopped"}};
  for (const auto& [reason, text] : reasons) EXPECT_EQ(ToString(reason), text);
  const std::vector<std::string> states = {"init",     "ready",   "run",   "paused",
                                           "stopping", "stopped", "error", "safe_stop"};
  for (std::size_t i = 0; i < kStates.size(); ++i) EXPECT_EQ(ToString(kStates[i]), states[i]);
  const std::vector<std::string> events = {
      "configured", "start",    "pause",       "stop_request", "finish_reached",
      "qos_abort",  "io_fault", "model_fault", "drained",      "reset", "peer_stopped"};
  for (std::size_t i = 0; i < kEvents.size(); ++i) EXPECT_EQ(ToString(kEvents[i]), events[i]);
  EXPECT_STREQ(ToString(Outcome::kRejected), "rejected");
  EXPECT_EQ(ReasonOf(E::kStart), StopReason::kNone);
  EXPECT_EQ(ReasonOf(E::kFinishReached), StopReason::kFinished);
  EXPECT_EQ(ReasonOf(E::kPeerStopped), StopReason::kPeerStopped);
}

// The seed ECS framework's commands (docs/lifecycle.md): initialise = set up, then
// `configured`; start = `start` (also resumes from pause); stop = `stop_request`;
// pause = `pause`; reset = `reset` (only once stopped); quit = exit when terminal.
TEST(Lifecycle, SeedCommandSequences) {
  Lifecycle machine;
  // initialise, start, pause, start (resume), stop
  EXPECT_EQ(machine.Handle(E::kConfigured).to, S::kReady);
  EXPECT_EQ(machine.Handle(E::kStart).to, S::kRun);
  EXPECT_EQ(machine.Handle(E::kPause).to, S::kPaused);
  EXPECT_FALSE(machine.rules().steps_model);
  EXPECT_EQ(machine.Handle(E::kStart).to, S::kRun);
  EXPECT_EQ(machine.Handle(E::kStopRequest).to, S::kStopping);
  EXPECT_EQ(machine.Handle(E::kDrained).to, S::kStopped);
  EXPECT_TRUE(machine.rules().terminal);  // quit is accepted here
  // reset, then initialise again
  EXPECT_EQ(machine.Handle(E::kReset).to, S::kInit);
  EXPECT_EQ(machine.Handle(E::kConfigured).to, S::kReady);
  // The seed resets a running machine directly; here that is refused (stop first).
  EXPECT_EQ(machine.Handle(E::kStart).to, S::kRun);
  EXPECT_EQ(machine.Handle(E::kReset).outcome, Outcome::kRejected);
  EXPECT_FALSE(machine.rules().terminal);  // quit is refused while running, as in the seed
}

}  // namespace
}  // namespace hiltwin::lifecycle

namespace hiltwin::lifecycle {
namespace {
static_assert(noexcept(std::declval<Lifecycle&>().Handle(Event::kStart)));
static_assert(noexcept(Next(State::kRun, Event::kPause)));
}  // namespace
}  // namespace hiltwin::lifecycle
