#include "wire_lockstep.h"

#include <atomic>

#include "hiltwin/kernel_glue/shared_wait.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "wire_guard.h"

namespace hiltwin::io {

namespace {

/// Why the lockstep broke, seen from the twin (column 0) or the ECS (column 1).
constexpr const char* kPeerGone[2] = {
    "wire: lockstep: the ECS process is gone (killed or crashed) while this twin waited for "
    "its turn; outputs went safe: restart both sides",
    "wire: lockstep: the twin process is gone (killed or crashed) while this ECS waited for "
    "its turn; outputs went safe: restart both sides"};
constexpr const char* kPeerHung[2] = {
    "wire: lockstep: the ECS stopped taking its turns (hung, stopped with SIGSTOP, or lost its "
    "heartbeat) while this twin waited; outputs went safe: restart both sides",
    "wire: lockstep: the twin stopped taking its turns (hung, stopped with SIGSTOP, or lost its "
    "heartbeat) while this ECS waited; outputs went safe: restart both sides"};
constexpr const char* kPeerNew[2] = {
    "wire: lockstep: another ECS process took the wire during the run; a lockstep run cannot "
    "take a new peer: restart both sides",
    "wire: lockstep: another twin process took the wire during the run; a lockstep run cannot "
    "take a new peer: restart both sides"};

}  // namespace

WireBus::LockstepClock::LockstepClock(WireBus& bus) noexcept
    : bus_(bus), ecs_side_(bus.side_ == Image::kIcoboard) {}

WireSide& WireBus::LockstepClock::self() noexcept {
  return ecs_side_ ? bus_.segment_->ecs : bus_.segment_->twin;
}

const WireSide& WireBus::LockstepClock::peer() const noexcept {
  return ecs_side_ ? bus_.segment_->twin : bus_.segment_->ecs;
}

void WireBus::LockstepClock::Publish(std::int64_t value) noexcept {
  WireSegment& seg = *bus_.segment_;
  bus_.guard_->own_lockstep_ns = value;
  self().lockstep_ns.store(value, std::memory_order_seq_cst);
  if (value == wire::kLockstepRunning) return;  // nobody waits for a side to take its turn
  // The peer sleeps only after counting itself in lockstep_sleepers and reading
  // lockstep_turns: either it sees this bump (and does not sleep) or this side sees it counted.
  seg.lockstep_turns.fetch_add(1, std::memory_order_seq_cst);
  if (seg.lockstep_sleepers.load(std::memory_order_seq_cst) != 0) {
    kernel_glue::SharedWakeAll(seg.lockstep_turns);
  }
}

void WireBus::LockstepClock::Leave() noexcept {
  if (bus_.guard_->own_lockstep_ns != wire::kLockstepLeft) Publish(wire::kLockstepLeft);
}

bool WireBus::LockstepClock::MayRun(kernel_glue::TimeNs t_ns, std::int64_t peer_ns) noexcept {
  if (peer_ns == wire::kLockstepLeft) return true;
  if (peer_ns == wire::kLockstepRunning) return false;
  if (peer_ns < 0) {
    bus_.guard_->Fail("wire: the %s's lockstep time is %lld ns (a time >= 0, -1 or the largest)",
                      ecs_side_ ? "twin" : "ECS", static_cast<long long>(peer_ns));
    return true;  // nothing more is read from the wire; the exchange reports the corruption
  }
  return peer_ns > t_ns || (peer_ns == t_ns && ecs_side_);
}

bool WireBus::LockstepClock::PeerStillTakingTurns() noexcept {
  const kernel_glue::TimeNs wall_ns = bus_.wall_.NowNs();
  if (!bus_.CheckSegment(wall_ns)) return false;
  bus_.Beat(wall_ns);  // the peer may be asleep on this side: keep this side's presence fresh
  const int column = ecs_side_ ? 1 : 0;
  // Its announced stop first: a peer that stopped cleanly and exited is gone too, but it ended
  // its run, it did not crash.
  const BusResult status = bus_.PeerStatus().result;
  if (status == BusResult::kPeerStopped) return false;  // its next exchange says why
  // Its process is gone (killed, crashed): the kernel dropped its presence lock at its death,
  // whether or not its parent has reaped it yet.
  if (!bus_.PeerProcessLives()) {
    // It may have announced its stop and exited since the status above: then it ended.
    if (bus_.PeerStatus().result != BusResult::kPeerStopped) broken_ = kPeerGone[column];
    return false;
  }
  const bool same_peer = peer().sessions.load(std::memory_order_relaxed) == peer_sessions_;
  if (status == BusResult::kOk && same_peer) return true;
  // Still starting (lockstep time 0: its loop has not waited yet). It counts as up from its
  // wait for this side, and beats again only once its loop waits or runs: under load (a
  // sanitizer, a busy machine) the moment in between may outlast the heartbeat timeout.
  // Alive, it is given kLockstepSetUpNs before it counts as hung.
  if (status == BusResult::kPeerLost && same_peer &&
      peer().lockstep_ns.load(std::memory_order_relaxed) == 0) {
    if (set_up_seen_ns_ < 0) set_up_seen_ns_ = wall_ns;
    if (wall_ns - set_up_seen_ns_ < kLockstepSetUpNs) return true;
  }
  // A new session, or a side attached but not beating yet: another process; else its
  // heartbeat is stale (hung, SIGSTOP).
  broken_ = status == BusResult::kOk || status == BusResult::kPeerAbsent ? kPeerNew[column]
                                                                          : kPeerHung[column];
  return false;
}

void WireBus::LockstepClock::WaitForTurn(kernel_glue::TimeNs t_ns) noexcept {
  if (t_ns <= now_ns_) return;  // no time passes: this side keeps the turn it holds
  ++counts_.waits;
  if (broken_ != nullptr || !bus_.guard_->ok()) {
    now_ns_ = t_ns;  // the lockstep is over; the next exchange reports why and the run ends
    return;
  }
  // The loop's first wait: the peer is up (the session waited for it); a later session on
  // the peer's side is another process, which a lockstep run cannot take.
  if (counts_.waits == 1) peer_sessions_ = peer().sessions.load(std::memory_order_relaxed);
  WireSegment& seg = *bus_.segment_;
  // A wait is a sign of life: the peer that gets the turn now may look at this side's
  // heartbeat before this side transfers again (after a long set-up, a long log wait). Before
  // the publish, which hands the turn over: the peer must find the beat already there.
  bus_.Beat(bus_.wall_.NowNs());
  Publish(t_ns);
  bool handed_over = false;
  kernel_glue::TimeNs waiting_since_ns = 0;
  kernel_glue::TimeNs looked_ns = 0;  // when the peer was last looked at
  for (;;) {
    if (MayRun(t_ns, peer().lockstep_ns.load(std::memory_order_seq_cst))) break;
    const kernel_glue::TimeNs wall_ns = bus_.wall_.NowNs();
    if (!handed_over) {
      handed_over = true;
      ++counts_.handovers;
      waiting_since_ns = looked_ns = wall_ns;
    }
    if (wall_ns - waiting_since_ns < kLockstepSpinNs) {
      kernel_glue::SpinPause();
      continue;
    }
    if (wall_ns - looked_ns >= kLockstepSliceNs) {
      if (!PeerStillTakingTurns()) break;
      // A stop signal ends a wait for a peer that is alive but does not take its turn (its
      // loop stuck in a step): this side's cycle then stops the run. Out of turn, but a stop
      // by signal lands at no fixed virtual time anyway.
      if (kernel_glue::StopRequested()) break;
      looked_ns = wall_ns;
    }
    seg.lockstep_sleepers.fetch_add(1, std::memory_order_seq_cst);
    const std::uint32_t seen = seg.lockstep_turns.load(std::memory_order_seq_cst);
    if (!MayRun(t_ns, peer().lockstep_ns.load(std::memory_order_seq_cst))) {
      ++counts_.sleeps;
      kernel_glue::SharedWait(seg.lockstep_turns, seen, kLockstepSliceNs);
    }
    seg.lockstep_sleepers.fetch_sub(1, std::memory_order_seq_cst);
  }
  if (broken_ == nullptr && bus_.guard_->ok()) Publish(wire::kLockstepRunning);
  now_ns_ = t_ns;
}

}  // namespace hiltwin::io
