#pragma once
/// The IcoBoard drivers: IcoBoard (the ECS's board: PWM out, encoder counts in) and
/// IcoBoardInverse (the twin's board: encoder positions out, PWM in). Same code on every backend:
/// they see only a SpiBus, through the timing wrapper. Init() is start-up code (may allocate,
/// returns a message); every per-cycle call is noexcept, allocation-free and returns a status.

#include <array>
#include <cstdint>
#include <string>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/exchange_status.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/io/spi_bus.h"

namespace hiltwin::io {

/// Link counters. "Received" means the answer passed every check and was used. Sent and
/// received are kept apart per kind, so that frames_sent is the number of data exchanges a user
/// asked for, not that plus the INIT (and its retries) and the TEST loop-backs; the error
/// counters cover every kind (a damaged INIT or TEST answer is as much a link error).
struct LinkCounters {
  std::uint64_t frames_sent = 0;           ///< data frames (ALL, per-channel read-backs)
  std::uint64_t frames_received = 0;       ///< data frames answered and used
  std::uint64_t init_frames_sent = 0;      ///< INIT, retries included (INIT resets the counters first)
  std::uint64_t init_frames_received = 0;
  std::uint64_t test_frames_sent = 0;      ///< TEST loop-backs
  std::uint64_t test_frames_received = 0;  ///< answered; whether the echo matched is the caller's
  std::uint64_t frames_corrupted = 0;      ///< any kind
  std::uint64_t frames_missed = 0;         ///< any kind
  std::uint64_t faults = 0;
  std::uint64_t pulse_limit_events = 0;  ///< answers whose board flagged kStatusPulseLimit
  std::uint64_t counts_over_limit = 0;   ///< channel changes larger than MaxCountsPerStep
};

/// Result of INIT and the identity check (start-up, not real-time).
struct InitResult {
  bool ok = false;
  bool image_known = false;       ///< identity matched one of the two images
  Image found = Image::kIcoboard; ///< meaningful when image_known
  std::uint8_t identity = 0;
  std::uint32_t clock_divider = 0;  ///< divider the board accepted
  std::string message;              ///< empty when ok; thesis fig. 4.2 style otherwise
};

/// What the twin receives per cycle.
struct TwinInputs {
  std::array<std::int32_t, kChannels> pwm{};  ///< PWM reader values, [-2047, 2047]
  std::array<double, kChannels> duty{};       ///< pwm / 2048 (appendix G)
  std::array<bool, kChannels> pins{};         ///< digital inputs (the ECS's digital outputs)
  std::uint8_t board_status = 0;              ///< kStatus* bits of the answer
};

/// What the ECS receives per cycle.
struct EcsInputs {
  std::array<std::int32_t, kChannels> counts{};           ///< 14-bit relative counts
  std::array<std::int64_t, kChannels> absolute_counts{};  ///< unwrapped since INIT
  std::array<bool, kChannels> pins{};
  std::uint8_t board_status = 0;
};

/// The common part of both drivers: framing, sequence numbers, checks and counters.
class IcoBoardLink {
 public:
  /// `image` is the image this side needs on its board. `clock` times transfers (null:
  /// monotonic). The bus is not owned and must outlive the driver.
  IcoBoardLink(SpiBus& bus, Image image, const kernel_glue::Clock* clock = nullptr) noexcept;

  /// Sends INIT with `step_ns` (and, for the twin, the encoder clock divider), checks the
  /// identity, retries up to 3 times on a damaged answer. Throws std::invalid_argument when
  /// `step_ns` is outside [10 ns, 4.29 s]. Resets the counters.
  InitResult Init(std::int64_t step_ns);
  /// TEST frame: the board echoes `pattern` into `echo`. A mismatch is a count error for the
  /// caller to judge; the status covers the link only.
  ExchangeStatus Test(const std::array<std::uint8_t, 8>& pattern,
                      std::array<std::uint8_t, 8>& echo) noexcept;
  /// Digital outputs sent with every following data frame.
  void SetDigitalOutputs(const std::array<bool, kChannels>& pins) noexcept { pins_out_ = pins; }

  [[nodiscard]] Image image() const noexcept { return image_; }
  [[nodiscard]] bool initialised() const noexcept { return initialised_; }
  [[nodiscard]] std::int64_t step_ns() const noexcept { return step_ns_; }
  [[nodiscard]] std::uint32_t clock_divider() const noexcept { return clock_divider_; }
  [[nodiscard]] const LinkCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const TransferTiming& timing() const noexcept { return spi_.timing(); }
  [[nodiscard]] const char* bus_name() const noexcept { return spi_.bus().Name(); }

 protected:
  /// One exchange: encodes `request` (sequence filled in), transfers it and then a NOOP fetch
  /// (the next sequence number) in one bus transaction, decodes the fetch's MISO, the board's
  /// answer to `request`, into `answer` and checks it.
  ExchangeStatus Transact(Frame& request, Frame& answer) noexcept;
  /// Judges rx_ (the fetch's MISO) as the answer to `request`, decoded into `answer`: kOk, or
  /// the code and reason of the first check it fails, with that counter incremented.
  ExchangeStatus CheckAnswer(const Frame& request, Frame& answer) noexcept;
  /// Transact() of an ALL frame carrying `words`, word-wide (the per-cycle exchange).
  ExchangeStatus TransactAll(ChannelWords words, AllFrame& answer) noexcept;

  TimedSpi spi_;
  Image image_;
  bool initialised_ = false;
  std::int64_t step_ns_ = 0;
  std::uint32_t clock_divider_ = 0;
  std::int64_t counts_limit_ = 0;  ///< MaxCountsPerStep(step_ns_, clock_divider_)
  std::uint8_t sequence_ = 0;
  LinkCounters counters_{};
  std::array<bool, kChannels> pins_out_{};
  std::array<std::int64_t, kChannels> last_counts_{};         ///< twin: last positions the board acknowledged
  std::array<EncoderUnwrapper, kChannels> unwrappers_{};      ///< ECS: relative -> absolute

 private:
  /// Numbers and encodes the NOOP fetch into fetch_tx_ (a NOOP always encodes: true).
  bool EncodeFetch() noexcept;
  ExchangeStatus EncodeFault() noexcept;
  /// The request in tx_ and its fetch, one bus transaction; `check` judges rx_ as the answer.
  template <typename Check>
  ExchangeStatus TransferAndCheck(Opcode opcode, Check&& check) noexcept;
  /// CheckAnswer() of the answer to an ALL request numbered `sequence`.
  ExchangeStatus CheckAllAnswer(std::uint8_t sequence, AllFrame& answer) noexcept;
  /// The checks after decoding, in their order: decoded, not rejected, same sequence, same
  /// opcode, INITIALISED for a data frame.
  ExchangeStatus Judge(FrameError error, std::uint8_t answer_status, bool same_sequence,
                       bool same_opcode, bool data) noexcept;

  Frame request_{};
  Frame answer_{};
  FrameBytes tx_{};
  FrameBytes fetch_tx_{};
  FrameBytes request_rx_{};  ///< MISO of the request transfer (answers the previous fetch)
  FrameBytes rx_{};          ///< MISO of the fetch transfer: the answer to the request
};

/// The twin's driver (image icoboard_inverse).
class IcoBoardInverse : public IcoBoardLink {
 public:
  explicit IcoBoardInverse(SpiBus& bus, const kernel_glue::Clock* clock = nullptr) noexcept
      : IcoBoardLink(bus, Image::kIcoboardInverse, clock) {}
  /// One cycle: sends the absolute encoder positions (wrapped to 14 bits here, appendix G) and
  /// receives the PWM measured since. On error `in` is untouched.
  ExchangeStatus Exchange(const std::array<std::int32_t, kChannels>& encoder_counts_out,
                          TwinInputs& in) noexcept;
};

/// The ECS's driver (image icoboard).
class IcoBoard : public IcoBoardLink {
 public:
  explicit IcoBoard(SpiBus& bus, const kernel_glue::Clock* clock = nullptr) noexcept
      : IcoBoardLink(bus, Image::kIcoboard, clock) {}
  /// One cycle: sends PWM values ([-2048, 2047], clamped) and receives the encoder counts.
  ExchangeStatus Exchange(const std::array<std::int32_t, kChannels>& pwm_out,
                          EcsInputs& in) noexcept;
};

}  // namespace hiltwin::io
