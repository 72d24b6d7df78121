#pragma once
/// The "wire" backend: the ECS process and the twin process each run their own emulated board;
/// a POSIX shared-memory segment (/dev/shm/hiltwin-wire-NAME) carries the wires between them:
/// the ECS board's PWM outputs drive the twin board's PWM reader, the twin board's encoder
/// emulator drives the ECS board's reader with pulses spread over the twin's period (so the ECS
/// sees the 1–2 period delay of thesis §3.7). Both boards read CLOCK_MONOTONIC, the clock both
/// processes share.
///
/// Lock-free: PWM is one 64-bit atomic; the encoder lines are a ring of the twin emulator's last
/// kEncoderLineHistory periods, each slot a single-writer seqlock, which the ECS board's
/// quadrature readers replay edge by edge (a slot overwritten before it was read is counted as a
/// resync, never waited for), so neither loop ever waits. Either side may start first or
/// restart; each side beats a heartbeat on every transfer and a peer whose heartbeat stops is
/// reported as kPeerLost. A peer that ends its run announces why (PeerLink::AnnounceStop) and is
/// then reported as kPeerStopped, so the other side can stop cleanly rather than as a fault.
/// While a side waits to start it keeps its heartbeat fresh with PeerLink::Poll. A side counts
/// as up from its first beat, which comes once its set-up is done: its first Poll, or (a run
/// that does not wait) its first transfer after INIT. Neither its attach nor its INIT exchange,
/// which happen while its command handles the options, beats: its real-time set-up follows
/// them and may outlast the heartbeat timeout, and until it is done its peer sees kPeerAbsent.
/// Whether a side's process still lives is a lock it holds on the segment's file
/// (kernel_glue::TakePresence), which the kernel drops at its death, even while its parent has
/// not reaped it yet; its pid is only its identity. A peer that died is forgotten when a new
/// process attaches, and the last live side out removes the segment. The segment's pages are
/// reserved when it is opened, so a full or too small /dev/shm is an error there, not a SIGBUS
/// at the first write.
///
/// Trust: the segment is created owner-only (0600) and refused when it exists with another
/// mode or owner, but any process of the same user can still write into it. So everything read
/// from it is checked before it is acted on (header, both sides' identities, PWM words, pin
/// bits, the ring's newest index and every encoder period's fields); an impossible value latches
/// BusResult::kWireCorrupted with a message naming the field, after which this side reads
/// nothing more from the wire (idle PWM, held encoder lines) and the run stops on an I/O fault
/// with safe outputs (this side's own board still answers). docs/spi-protocol.md, wire:NAME.
///
/// Time: in real time (WireClock::kRealtime) both boards read CLOCK_MONOTONIC. In lockstep
/// (WireClock::kLockstep, `--clock virtual` on both sides) the two processes share one virtual
/// time base instead (docs/lockstep.md): the bus owns a clock (lockstep_clock()) that the
/// session runs its loop on and both boards read, and a side that sleeps until its next release
/// waits until the other side has run everything that comes earlier, so each side's cycle k
/// happens at its release in that base, in a fixed order (at equal times the ECS first). The
/// heartbeat stays in wall time, so a peer that hangs or dies still ends this side within a
/// second. A side refuses a peer on the other clock: at attach, and while it waits to start.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/peer_link.h"
#include "hiltwin/io/spi_bus.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::io {

struct WireSegment;
class WireGuard;

/// A peer counts as lost when its heartbeat is older than max(this, 20 peer steps): long enough
/// that a SCHED_OTHER process on a loaded machine is not declared dead by a scheduling delay,
/// short enough that a crash ends the other side well within a second.
constexpr std::int64_t kWireMinHeartbeatTimeoutNs = 250'000'000;
/// In lockstep a loop may be busy for long between transfers (it waits for its log writer
/// rather than drop a row), so the process beats from its control thread every 100 ms
/// (PeerLink::KeepAlive) and its peer allows this much: a SIGSTOP still ends the peer's wait
/// within well under a second.
constexpr std::int64_t kWireLockstepHeartbeatTimeoutNs = 500'000'000;

/// Owner-only: the mode the segment is created with and must have when it exists.
constexpr unsigned kWireSegmentMode = 0600;

/// Which time base a wire side runs on; both sides of one wire must agree.
enum class WireClock : std::uint8_t {
  kRealtime,  ///< CLOCK_MONOTONIC (--clock realtime)
  kLockstep,  ///< one virtual time base shared with the peer (--clock virtual)
};

/// What one side's lockstep clock counted (benchmarks, tests).
struct LockstepCounts {
  std::uint64_t waits = 0;      ///< SleepUntilNs/SpendNs calls that moved this side's time
  std::uint64_t handovers = 0;  ///< of them: the peer held the turn first
  std::uint64_t sleeps = 0;     ///< futex sleeps (a hand-over that outlasted the spin)
};

class WireBus final : public SpiBus, public PeerLink {
 public:
  /// Attaches to (or creates) the segment of `name` as the side that owns a board of `side`
  /// (icoboard = ECS, icoboard_inverse = twin). Throws std::invalid_argument for a bad name
  /// and std::runtime_error when the segment cannot be used (not a regular file owned by this
  /// user with mode 0600, another layout, impossible contents, no room in /dev/shm for its
  /// pages) or that side is already attached by a live process. `board_image` (fault
  /// injection) is the image this side's emulated board carries, the side's own image when
  /// empty: the wrong one fails INIT's identity check.
  /// `clock`: the time base; a peer attached on the other one is refused (ClockMismatch).
  WireBus(const std::string& name, Image side, std::optional<Image> board_image = {},
          WireClock clock = WireClock::kRealtime);
  ~WireBus() override;
  WireBus(const WireBus&) = delete;
  WireBus& operator=(const WireBus&) = delete;

  BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override;
  /// Request and fetch against this side's board inside one sampling window, then one publish
  /// and heartbeat: the wire sees an exchange exactly as it saw a single transfer.
  BusStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                         const FrameBytes& fetch, FrameBytes& answer) noexcept override;
  [[nodiscard]] const char* Name() const noexcept override { return label_.c_str(); }

  /// This side's board model (fault injection, inspection).
  [[nodiscard]] EmulatedFpga& board() noexcept { return board_; }
  /// Lockstep: the shared virtual clock the session must run its loop on; null in real time.
  [[nodiscard]] kernel_glue::Clock* lockstep_clock() noexcept;
  [[nodiscard]] LockstepCounts lockstep_counts() const noexcept;
  /// Heartbeat status of the other side right now (no transfer).
  [[nodiscard]] BusStatus PeerStatus() const noexcept;
  BusStatus Poll() noexcept override;
  void AnnounceStop(StopCause cause) noexcept override;
  /// Lockstep: beats (heartbeat atomics only). Real time: nothing, the transfers beat.
  void KeepAlive() noexcept override;
  /// The twin emulator's period `index` as published on the wire (tests, diagnostics); false
  /// when it is not, or no longer, in the ring.
  [[nodiscard]] bool ReadEncoderPeriod(std::uint64_t index, EncoderPeriod& out) const noexcept;

  /// "/dev/shm/hiltwin-wire-NAME" (messages, tests).
  [[nodiscard]] static std::string SegmentPath(const std::string& name);
  /// "/hiltwin-wire-NAME". Throws std::invalid_argument unless NAME is 1–64 of [A-Za-z0-9_.-].
  static std::string SegmentName(const std::string& name);
  /// Removes the segment (tests, clean-up after crashes). No error when absent.
  static void Unlink(const std::string& name);

 private:
  class PwmWire;
  class EncoderWire;
  class LockstepClock;
  /// Registers this side in the segment (refusing a second live process on it) and clears
  /// the flags of a peer that died without detaching.
  void Attach();
  /// Unmaps the segment and closes its file (which drops this side's presence lock).
  void Release() noexcept;
  /// Whether a process holds the peer's presence lock: one that took the peer's side lives.
  /// One system call (cold paths only: start-up, a clock mismatch, a lockstep slice, detach).
  [[nodiscard]] bool PeerProcessLives() const noexcept;
  /// Whether the peer is there now: attached, and its process lives.
  [[nodiscard]] bool PeerAlive() const noexcept;
  /// Puts this side's outputs on the wire and, once it is present, beats.
  void Publish(std::int64_t now_ns) noexcept;
  /// Checks the header and both sides' identity fields at `now_ns`; false (and the guard
  /// latched) when the segment holds what no hiltwin process writes.
  bool CheckSegment(std::int64_t now_ns) noexcept;
  /// The peer's pid may change only with a new session (after a short settling time).
  bool CheckPeerIdentity(std::int64_t now_ns) noexcept;
  /// This side's result: the latched corruption, a broken lockstep, else the peer's status.
  [[nodiscard]] BusStatus Status() const noexcept;
  /// The peer's clock when it differs from this side's (kPeerMismatch), else kOk.
  [[nodiscard]] BusStatus ClockMismatch() const noexcept;
  void Beat(std::int64_t now_ns) noexcept;
  /// Reads the digital inputs off the wire into the board, runs `transfers` (callable) inside
  /// the twin's sampling window, publishes and returns the peer's status.
  template <typename Transfers>
  BusStatus RunOnBoard(Transfers&& transfers) noexcept;

  std::string label_;
  std::string segment_name_;
  Image side_;
  WireClock clock_kind_;
  /// Wall time: heartbeats, liveness and the checks of the peer's wall-clock fields.
  kernel_glue::MonotonicClock wall_;
  std::unique_ptr<LockstepClock> lockstep_;  ///< lockstep only
  /// What the board and the wire's time model read: wall_, or the lockstep clock.
  const kernel_glue::Clock* board_clock_;
  EmulatedFpga board_;
  WireSegment* segment_ = nullptr;
  int fd_ = -1;  ///< the segment's file, open while attached: it holds the presence lock
  std::int32_t pid_ = 0;
  /// Whether this side's set-up is done (its first Poll, or a transfer after INIT): its
  /// transfers beat only from then on. Only the thread that polls or transfers touches it.
  bool present_ = false;
  std::unique_ptr<WireGuard> guard_;
  std::unique_ptr<PwmWire> pwm_wire_;
  std::unique_ptr<EncoderWire> encoder_wire_;
};

}  // namespace hiltwin::io
