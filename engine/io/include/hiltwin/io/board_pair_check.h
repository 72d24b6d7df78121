#pragma once
/// The end-to-end link check of `hiltwin io-test --io mock` (thesis §5.5, Table 5.2): a twin
/// board and an ECS board in one process, each behind its own emulated bus and driver, joined by
/// their wires (EmulatorToReaderLink: twin emulator -> A/B lines -> ECS quadrature readers;
/// GeneratorToReaderLink: ECS PWM generator -> twin PWM reader). Each data step the ECS sends a
/// known PWM pattern that the twin must read back exactly, and the twin sends a known encoder
/// pattern that the ECS must decode exactly, edge by edge; messages are counted sent, received
/// and missed end to end, as Table 5.2 counts them.
///
/// Timing: the mock boards have no clock; each board's time is (its data frames since INIT) ×
/// (step from INIT), and both use the same step. Data step k happens at board time k·step on
/// both: the ECS frame first (PWM message k out; the encoder position the twin sent at step
/// k − 1, whose pulses the emulator spread over the period that has just ended, in), then the
/// twin frame (PWM message k in, encoder message k out). So PWM arrives in the same step and an
/// encoder message one period later, the emulator's inherent delay (thesis §2.2.1); Finish()
/// gives the ECS the one more frame it needs to decode the last encoder message. Per-step calls
/// are noexcept and allocation-free.

#include <array>
#include <cstdint>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"

namespace hiltwin::io {

/// Encoder positions a link test sends: per channel, a walk up across an encoder wrap (absolute
/// ±8192 or ±24576, where the 14-bit position jumps from 8191 to −8192), a stop, one jump down
/// and one jump up of exactly the pulse limit, a walk back down across the wrap and a stop, over
/// and over. Every change fits in one period (at most the limit), so the ECS must decode each
/// position exactly one period later; both directions, all four cases of thesis Table 4.1, zero
/// changes and changes at the limit all occur. Channel c walks 13·(c + 1) counts per frame, so a
/// long run costs few edges per frame while the jumps still test the limit.
class EncoderTestPattern {
 public:
  /// `max_counts_per_step`: the twin board's limit (MaxCountsPerStep of its step and divider).
  explicit EncoderTestPattern(std::uint32_t max_counts_per_step) noexcept;
  /// Moves on to the next data frame's positions (absolute counts, starting from 0 at INIT).
  const std::array<std::int32_t, kChannels>& Next() noexcept;
  [[nodiscard]] const std::array<std::int32_t, kChannels>& positions() const noexcept {
    return positions_;
  }

 private:
  enum class Phase : std::uint8_t {
    kApproach,
    kWalkUp,
    kStopTop,
    kJumpDown,
    kJumpUp,
    kWalkDown,
    kStopBottom
  };
  struct Channel {
    std::int32_t bottom = 0;  ///< just below the wrap
    std::int32_t top = 0;     ///< bottom + limit: just above it
    std::int32_t walk = 1;    ///< counts per frame while walking
    Phase phase = Phase::kApproach;
  };
  [[nodiscard]] std::int32_t Advance(Channel& channel, std::int32_t position) const noexcept;

  std::int32_t limit_;
  std::array<Channel, kChannels> channels_{};
  std::array<std::int32_t, kChannels> positions_{};
};

/// The PWM value a link test sends on channel c in data frame k: sweeps [-2047, 2047] (what the
/// twin's reader measures exactly), channel c 511·c ahead of channel 0.
[[nodiscard]] std::int32_t PwmTestValue(std::int64_t k, std::size_t c) noexcept;

/// Messages one way, end to end (thesis Table 5.2).
struct MessageTally {
  std::uint64_t sent = 0;
  std::uint64_t received = 0;  ///< arrived with exactly the values sent
  std::uint64_t wrong = 0;     ///< arrived (the frame was good) with other values: count errors
  [[nodiscard]] std::uint64_t missed() const noexcept { return sent - received; }
};

/// The first value that did not arrive as sent, for the error message.
struct FirstMiss {
  std::int64_t frame = -1;  ///< data frame of the message; -1 = none
  std::size_t channel = 0;
  std::int64_t sent = 0;
  std::int64_t read = 0;    ///< what arrived (ECS: unwrapped absolute counts)
  const char* reason = "";  ///< the frame's error when the message did not arrive at all
};

/// Faults a link test can inject, to show that it catches them.
struct LinkFault {
  enum class Kind : std::uint8_t {
    kNone,
    kStuckEmulator,  ///< the twin board's encoder emulator emits no pulses
    kStuckReader,    ///< the ECS board's quadrature readers see no edges
    kCorruptCounts,  ///< the ECS board's answers (the counts) leave with one bit flipped
  };
  Kind kind = Kind::kNone;
  std::int64_t at_frame = 0;  ///< first data step affected
  std::int64_t frames = 1;    ///< data steps affected
};

/// Both drivers' INIT results.
struct PairInit {
  InitResult twin;
  InitResult ecs;
  [[nodiscard]] bool ok() const noexcept { return twin.ok && ecs.ok; }
};

/// How both sides' frames of one step went.
struct PairStatus {
  ExchangeStatus ecs;
  ExchangeStatus twin;
  /// The link is down on either side (the check cannot go on).
  [[nodiscard]] const char* fault() const noexcept;
};

/// Everything the check counted beyond the drivers' own counters.
struct PairTally {
  MessageTally encoder;  ///< twin -> ECS, through the emulator, the lines and the readers
  MessageTally pwm;      ///< ECS -> twin, through the generator and the reader
  FirstMiss first_encoder_miss;
  FirstMiss first_pwm_miss;
  std::uint64_t test_echo_errors = 0;  ///< TEST answers whose payload was not the one sent
  std::uint64_t wraps_up = 0;  ///< emulator periods that crossed the wrap counting up (Table 4.1 D)
  std::uint64_t wraps_down = 0;  ///< ... counting down (Table 4.1 C)
};

/// The two boards and their drivers; see the file comment.
class BoardPairCheck {
 public:
  /// The board images default to the right ones; another image tests the identity check.
  explicit BoardPairCheck(Image twin_board_image = Image::kIcoboardInverse,
                          Image ecs_board_image = Image::kIcoboard) noexcept;
  BoardPairCheck(const BoardPairCheck&) = delete;
  BoardPairCheck& operator=(const BoardPairCheck&) = delete;

  /// INIT on the twin's board, then on the ECS's, with the same step (start-up, may allocate).
  /// Sizes the encoder pattern to the twin board's pulse limit.
  PairInit Init(std::int64_t step_ns);
  /// The fault to inject (before the first step).
  void Inject(const LinkFault& fault) noexcept { fault_ = fault; }

  /// One data step: the ECS frame, then the twin frame, both checked (see the file comment).
  PairStatus DataStep() noexcept;
  /// A TEST loop-back on both drivers with `pattern`.
  PairStatus TestStep(const std::array<std::uint8_t, 8>& pattern) noexcept;
  /// The ECS's last frame, which decodes the twin's last encoder message (PWM 0: motors off).
  PairStatus Finish() noexcept;

  [[nodiscard]] const PairTally& tally() const noexcept { return tally_; }
  [[nodiscard]] std::int64_t data_steps() const noexcept { return step_; }
  [[nodiscard]] const IcoBoardInverse& twin() const noexcept { return twin_; }
  [[nodiscard]] const IcoBoard& ecs() const noexcept { return ecs_; }
  [[nodiscard]] const EmulatedFpga& twin_board() const noexcept { return twin_board_; }
  [[nodiscard]] const EmulatedFpga& ecs_board() const noexcept { return ecs_board_; }

 private:
  void ApplyFault() noexcept;
  /// Compares what the ECS just read with encoder message `frame` (`sent` positions).
  void CheckEncoder(const ExchangeStatus& status, std::int64_t frame,
                    const std::array<std::int32_t, kChannels>& sent) noexcept;
  void CheckPwm(const ExchangeStatus& status, std::int64_t frame,
                const std::array<std::int32_t, kChannels>& sent) noexcept;
  void CountWraps() noexcept;

  EmulatedFpga twin_board_;
  EmulatedFpga ecs_board_;
  EmulatorToReaderLink encoder_wires_{twin_board_};
  GeneratorToReaderLink pwm_wires_{ecs_board_};
  EmulatedSpiBus twin_bus_{twin_board_, "mock"};
  EmulatedSpiBus ecs_bus_{ecs_board_, "mock"};
  IcoBoardInverse twin_{twin_bus_};
  IcoBoard ecs_{ecs_bus_};

  EncoderTestPattern pattern_{kMaxRepresentablePulses - 1};
  LinkFault fault_{};
  std::int64_t step_ = 0;  ///< data steps done
  std::array<std::int32_t, kChannels> pwm_out_{};
  std::array<std::int32_t, kChannels> encoder_sent_{};  ///< the twin's last encoder message
  TwinInputs twin_in_{};
  EcsInputs ecs_in_{};
  PairTally tally_{};
};

}  // namespace hiltwin::io
