#pragma once
/// The wire backend's shared segment (/dev/shm/hiltwin-wire-NAME), as both processes map it.
/// Only wire_bus.cpp reads and writes it in a run; it is public so that tests (and the vandal
/// process of the hostile-memory tests) can write exactly the field they mean to damage.
/// Zero-filled memory is a valid initial state of every field.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "hiltwin/io/encoder_lines.h"
#include "hiltwin/lockfree/seqlock.h"

namespace hiltwin::io {

namespace wire {
constexpr std::uint64_t kMagic = 0x6869'6C74'7769'7265ULL;  // "hiltwire"
// 2: encoder periods in a ring; 3: stop causes; 4: seqlock slots of 64-bit words (no fences);
// 5: each side's clock and the lockstep's turn words; 6: a side's process is present while it
// holds its presence lock (kEcsPresenceByte): a version-5 side holds none and would look dead
constexpr std::uint32_t kLayoutVersion = 6;
constexpr std::uint32_t kFresh = 0;
constexpr std::uint32_t kInitialising = 1;
constexpr std::uint32_t kReady = 2;
/// last_beat_ns from Attach until the side's first beat: attached, still setting up (INIT while
/// its command handles the options, then the real-time set-up, pre-faulting, under load or a
/// sanitizer easily longer than the heartbeat timeout). A side first beats once that is done:
/// at its first Poll (it waits for its peer) or, when it does not wait, at its first transfer
/// after INIT. Its peer waits for that beat: an earlier one would count a side that is not yet
/// polling as up, and then as lost once its set-up outlasts the timeout. No CLOCK_MONOTONIC
/// reading is 0.
constexpr std::int64_t kNoBeatYet = 0;
/// The byte of the segment's file on which each side holds its presence lock while attached
/// (kernel_glue::TakePresence): the kernel drops it at the holder's death, reaped or not, so
/// whether a side's process is there is asked of the lock, never of its pid.
constexpr std::int64_t kEcsPresenceByte = 0;
constexpr std::int64_t kTwinPresenceByte = 1;
/// twin_sampling_ns when the twin is not inside a transfer.
constexpr std::int64_t kNotSampling = std::numeric_limits<std::int64_t>::max();
/// Words of one encoder period: start_ns, subticks << 32 | divider, start_counts (4 × 16),
/// pulses (4 × 16), directions (4 × 8).
constexpr std::size_t kPeriodWords = 5;
/// WireSide::clock: which time base a side runs on. 0 until it attaches.
constexpr std::uint32_t kClockUnset = 0;
constexpr std::uint32_t kClockRealtime = 1;  ///< CLOCK_MONOTONIC, each side on its own
constexpr std::uint32_t kClockLockstep = 2;  ///< the shared virtual time base (--clock virtual)
/// WireSide::lockstep_ns besides a virtual time (>= 0) the side waits for its turn at:
constexpr std::int64_t kLockstepRunning = -1;  ///< it holds the turn: the time base stands still
constexpr std::int64_t kLockstepLeft = std::numeric_limits<std::int64_t>::max();  ///< it stopped
}  // namespace wire

/// One process's presence on the wire. `attached` and `pid` say who attached; whether that
/// process still lives is the presence lock's to say (wire::kEcsPresenceByte).
struct WireSide {
  std::atomic<std::uint64_t> heartbeat;
  std::atomic<std::int64_t> last_beat_ns;
  std::atomic<std::int64_t> step_ns;
  std::atomic<std::int32_t> pid;
  std::atomic<std::uint32_t> attached;
  std::atomic<std::uint32_t> sessions;
  std::atomic<std::uint32_t> stop_cause;  ///< a StopCause; kNone while running
  std::atomic<std::uint32_t> clock;       ///< wire::kClockRealtime or kClockLockstep
  /// Lockstep only: the virtual time of this side's next event while it waits for its turn,
  /// wire::kLockstepRunning while it runs, wire::kLockstepLeft once it stopped. 0 from its
  /// attach until its loop waits for the first release: its set-up happens at time 0.
  std::atomic<std::int64_t> lockstep_ns;
};

/// One encoder period in the ring: a single-writer seqlock whose tag is the period's index.
using WirePeriod = lockfree::SeqlockSlot<wire::kPeriodWords>;

/// The shared segment. Zero-filled memory is a valid initial state of every field.
struct WireSegment {
  std::atomic<std::uint32_t> init_state;
  std::atomic<std::uint32_t> attach_count;
  std::atomic<std::uint64_t> magic;
  std::atomic<std::uint32_t> version;
  std::atomic<std::uint32_t> size;
  WireSide ecs;
  WireSide twin;
  /// ECS -> twin: four packed PWM words (direction, pin, magnitude), 16 bits each.
  std::atomic<std::uint64_t> pwm_words;
  std::atomic<std::uint32_t> twin_pins;  ///< bit c = digital output c of the twin
  /// Twin -> ECS encoder lines: the twin's emulator periods, newest index last published.
  std::atomic<std::uint64_t> encoder_newest;
  /// The twin's clock when it began the transfer in progress (kNotSampling outside one): a
  /// period it is about to publish starts no earlier, so the ECS replays edges only up to here.
  std::atomic<std::int64_t> twin_sampling_ns;
  WirePeriod encoder_periods[kEncoderLineHistory];
  /// Lockstep: bumped whenever a side publishes a new lockstep_ns; the futex word a side
  /// sleeps on while the other holds the turn (kernel_glue/shared_wait.h).
  std::atomic<std::uint32_t> lockstep_turns;
  std::atomic<std::uint32_t> lockstep_sleepers;  ///< sides asleep on lockstep_turns
};
static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free &&
                  std::atomic<std::uint32_t>::is_always_lock_free,
              "the wire needs address-free (lock-free) atomics to work across processes");

}  // namespace hiltwin::io
