#pragma once
// The wire's lockstep clock (wire_bus.h, "Time"; docs/lockstep.md): private to io.
#include <cstdint>

#include "hiltwin/io/wire_bus.h"
#include "hiltwin/io/wire_segment.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::io {

/// One side's view of the time base the two processes share. Each side keeps its own reading
/// (NowNs) and publishes, while it waits, the virtual time of its next event
/// (WireSide::lockstep_ns). A side may move its time to t once the peer waits for a later time,
/// or for the same time when this side is the ECS (at equal times the controller samples
/// first, then the twin reads what it wrote, as in the in-process rig); otherwise the peer
/// holds the turn. While one side runs, the other's time stands still, so every access to the
/// wire happens in one order, fixed by the virtual times alone: the run is exact and
/// repeatable whatever the machine does.
///
/// The wait spins for kLockstepSpinNs (a hand-over between two busy CPUs costs well under a
/// microsecond), then sleeps on the segment's futex word in slices of kLockstepSliceNs. After
/// each slice it beats this side's heartbeat (wall time) and looks at the peer: a peer that
/// stopped releases the wait (its stop is reported by the next exchange); a peer that is gone,
/// hung or restarted breaks the lockstep (broken(): the bus then reports kPeerLost), so no
/// wait outlasts the heartbeat timeout (kWireLockstepHeartbeatTimeoutNs: the peer's control
/// thread beats for it while its loop is busy) by more than a slice. A stop signal ends a wait
/// too, so a peer whose loop is stuck cannot hold this side forever.
class WireBus::LockstepClock final : public kernel_glue::Clock {
 public:
  /// Spinning beyond this costs more than the futex sleep it avoids.
  static constexpr kernel_glue::TimeNs kLockstepSpinNs = 20'000;
  static constexpr kernel_glue::TimeNs kLockstepSliceNs = 10'000'000;
  /// How long a live peer may stay starting (between its last poll for this side and its
  /// loop's first wait) without a heartbeat before it counts as hung.
  static constexpr kernel_glue::TimeNs kLockstepSetUpNs = 30'000'000'000;

  /// Binds to `bus`, whose segment it reaches only once the loop waits (after the bus mapped it).
  explicit LockstepClock(WireBus& bus) noexcept;

  [[nodiscard]] kernel_glue::TimeNs NowNs() const noexcept override { return now_ns_; }
  /// Waits for this side's turn at `deadline_ns`, then reads it. At once when not later.
  void SleepUntilNs(kernel_glue::TimeNs deadline_ns) noexcept override { WaitForTurn(deadline_ns); }
  /// Busy time is time too: the peer runs what falls inside it first.
  void SpendNs(kernel_glue::TimeNs duration_ns) noexcept override {
    if (duration_ns > 0) WaitForTurn(now_ns_ + duration_ns);
  }
  [[nodiscard]] bool IsVirtual() const noexcept override { return true; }

  /// This side has stopped: the peer never waits for it again (AnnounceStop, detach).
  void Leave() noexcept;
  /// Why the lockstep broke (static text), null while it holds.
  [[nodiscard]] const char* broken() const noexcept { return broken_; }
  [[nodiscard]] LockstepCounts counts() const noexcept { return counts_; }

 private:
  void WaitForTurn(kernel_glue::TimeNs t_ns) noexcept;
  /// Whether this side may move its time to `t_ns` while the peer publishes `peer_ns`.
  [[nodiscard]] bool MayRun(kernel_glue::TimeNs t_ns, std::int64_t peer_ns) noexcept;
  /// After a slice of sleep: beats, checks the segment and the peer. False when the wait ends
  /// without the peer's turn (it stopped, or broken_ / the guard now says why).
  [[nodiscard]] bool PeerStillTakingTurns() noexcept;
  void Publish(std::int64_t value) noexcept;
  /// This side's and the peer's entries (the segment is mapped after this clock exists).
  [[nodiscard]] WireSide& self() noexcept;
  [[nodiscard]] const WireSide& peer() const noexcept;

  WireBus& bus_;
  bool ecs_side_;
  kernel_glue::TimeNs now_ns_ = 0;
  std::uint32_t peer_sessions_ = 0;  ///< the peer's session count when the loop began
  kernel_glue::TimeNs set_up_seen_ns_ = -1;  ///< wall time this side first saw the peer in set-up
  const char* broken_ = nullptr;
  LockstepCounts counts_{};
};

}  // namespace hiltwin::io
