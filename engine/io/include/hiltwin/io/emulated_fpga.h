#pragma once
/// The emulated FPGA ("mock" backend): a device model of either image behind an emulated SPI
/// bus, bus and device kept apart as in Zephyr's spi_emul, so the drivers run unchanged. The
/// board's inputs come from signal-source interfaces (not owned); fault-injection hooks corrupt,
/// drop or delay frames, stick the encoder and answer as the wrong image.
///
/// Time: with no clock, the board's time is (data frames since INIT) × (step from INIT): the
/// k-th ALL frame after INIT happens at k·step, exactly as on the twin's virtual clock. With a
/// clock (wire backend), the board reads that clock at every ALL frame.
///
/// Pipelined answers (docs/spi-protocol.md, "Pipelined answers"): a full-duplex slave shifts out
/// byte 0 while byte 0 of the request is still arriving, so transfer n carries the answer to
/// request n-1. The board keeps an answer register (all zeros at construction, which the host
/// reads as an idle MISO); each transfer shifts it out, then the board acts on the request that
/// arrived and replaces the register with the answer to it. The driver fetches that answer with
/// a NOOP transfer (IcoBoardLink).

#include <array>
#include <cstdint>
#include <optional>

#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/encoder_lines.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/io/spi_bus.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::io {

/// Drives the twin board's PWM reader: the duty (in [-1, 1], sign = direction pin) of each
/// channel's PWM input at board time `t_ns`. Called on the loop's thread, once per ALL frame.
class PwmSignalSource {
 public:
  virtual ~PwmSignalSource() = default;
  virtual void DutyAt(std::int64_t t_ns, std::array<double, kChannels>& duty_out) noexcept = 0;
};

/// Fault-injection hooks (ros2_control mock_components). NOOPs (the driver's fetches) are
/// skipped: request faults are consumed one per request whose opcode byte is not NOOP, answer
/// faults one per answer to such a request, so "the next N" counts the frames whose answers the
/// host reads.
struct FaultInjection {
  std::uint32_t corrupt_requests = 0;  ///< next N requests arrive with one bit flipped
  std::uint32_t corrupt_answers = 0;   ///< next N answers leave with one bit flipped
  std::uint32_t drop_answers = 0;      ///< next N answers are not sent (MISO idles high)
  std::uint32_t delay_answers = 0;     ///< next N answers are replaced by what the board sent
                                       ///< in the transfer before
  bool stick_encoder = false;          ///< twin: the emulator emits nothing; ECS: the readers see nothing
  std::optional<Image> answer_as_image;  ///< INIT answers this image's identity
};

/// Anything that answers SPI frames: the device side of an emulated bus.
class SpiDevice {
 public:
  virtual ~SpiDevice() = default;
  virtual void Exchange(const FrameBytes& mosi, FrameBytes& miso) noexcept = 0;
};

/// The board model. ECS image: PWM generator + quadrature encoder readers, which decode the A/B
/// edges of an EncoderLineSource (the twin's emulator) up to each ALL frame. Twin image: PWM
/// reader + encoder emulator, which publishes every period to an EncoderLineSink. Writes happen
/// only in ALL frames; per-channel PWMc/ENCc frames read one channel back; TEST echoes its
/// payload.
class EmulatedFpga final : public SpiDevice {
 public:
  explicit EmulatedFpga(Image image, const kernel_glue::Clock* clock = nullptr) noexcept;

  /// One transfer: `miso` is the answer register as it stood when the transfer began (the
  /// answer to the previous request, answer faults applied); then the board acts on `mosi` and
  /// the register becomes the answer to it.
  void Exchange(const FrameBytes& mosi, FrameBytes& miso) noexcept override;

  /// Input sources (not owned; null = idle line: duty 0 / count held).
  void SetPwmSource(PwmSignalSource* source) noexcept { pwm_source_ = source; }
  void SetEncoderSource(EncoderLineSource* source) noexcept { encoder_source_ = source; }
  /// Twin image: where the emulator's periods go (not owned; null = nowhere).
  void SetEncoderSink(EncoderLineSink* sink) noexcept { encoder_sink_ = sink; }
  /// Levels of the digital input pins (the other side's digital outputs).
  void SetDigitalInputs(const std::array<bool, kChannels>& pins) noexcept {
    pins_in_ = pins;
    pwm_memo_valid_ = false;  // the twin's answer words carry them
  }
  /// Fault-injection hooks, changed between transfers.
  [[nodiscard]] FaultInjection& faults() noexcept { return faults_; }

  [[nodiscard]] Image image() const noexcept { return image_; }
  [[nodiscard]] bool initialised() const noexcept { return initialised_; }
  [[nodiscard]] std::int64_t step_ns() const noexcept { return step_ns_; }
  [[nodiscard]] std::uint32_t clock_divider() const noexcept { return divider_; }
  /// Board time of the latest ALL frame.
  [[nodiscard]] std::int64_t time_ns() const noexcept { return time_ns_; }
  [[nodiscard]] std::uint64_t data_frames() const noexcept { return data_frames_; }
  [[nodiscard]] std::uint64_t requests_rejected() const noexcept { return requests_rejected_; }

  /// Twin image: the encoder emulator of channel c.
  [[nodiscard]] const EncoderEmulator& encoder(std::size_t c) const noexcept { return emulators_[c]; }
  /// Twin image: PWM values last measured by the reader.
  [[nodiscard]] const std::array<std::int32_t, kChannels>& pwm_measured() const noexcept {
    return pwm_values_;
  }
  /// ECS image: PWM values the generator outputs (from the latest ALL frame).
  [[nodiscard]] const std::array<std::int32_t, kChannels>& pwm_output() const noexcept {
    return pwm_values_;
  }
  /// ECS image: the readers' 14-bit counts from the latest ALL frame.
  [[nodiscard]] const std::array<std::int32_t, kChannels>& encoder_counts() const noexcept {
    return counts_;
  }
  /// ECS image: the quadrature readers and their error counters.
  [[nodiscard]] const EncoderLineReader& encoder_lines() const noexcept { return lines_; }
  /// Digital outputs set by the host in the latest ALL frame.
  [[nodiscard]] const std::array<bool, kChannels>& pins_out() const noexcept { return pins_out_; }

 private:
  void HandleRequest(const Frame& request, Frame& answer) noexcept;
  void HandleInit(const Frame& request, Frame& answer) noexcept;
  /// An ALL frame's sampling moment: takes the request's channel words, returns the answer's.
  ChannelWords HandleAll(ChannelWords request_words) noexcept;
  ChannelWords SampleTwin(ChannelWords encoder_words, std::int64_t t_ns) noexcept;
  /// Twin image: the PWM reader on duty_scratch_: pwm_values_ and pwm_words_.
  void MeasurePwm() noexcept;
  ChannelWords SampleEcs(ChannelWords pwm_words, std::int64_t t_ns) noexcept;
  void FillReadback(Opcode opcode, Frame& answer) const noexcept;
  /// Shifts out the answer register, applying the answer faults to answers of non-NOOPs.
  void SendAnswer(FrameBytes& miso) noexcept;
  /// Decodes the request (after the request faults) and acts on it: the new answer register.
  void TakeRequest(const FrameBytes& mosi) noexcept;
  void ActOn(const FrameBytes& request_bytes) noexcept;
  /// ALL, the per-cycle request, decoded and answered word-wide.
  void TakeAll(const FrameBytes& request_bytes) noexcept;
  /// The answer to a request that failed its checks.
  void Reject(const FrameBytes& request_bytes) noexcept;
  /// `status` with INITIALISED and PULSE_LIMIT as the board stands.
  [[nodiscard]] std::uint8_t WithStateBits(std::uint8_t status) const noexcept;
  void ResetState() noexcept;
  /// Twin image: hands the periods just started to the sink.
  void PublishPeriod() noexcept;

  Image image_;
  const kernel_glue::Clock* clock_;
  PwmSignalSource* pwm_source_ = nullptr;
  EncoderLineSource* encoder_source_ = nullptr;
  EncoderLineSink* encoder_sink_ = nullptr;
  FaultInjection faults_{};

  bool initialised_ = false;
  bool pulse_limit_ = false;
  std::int64_t step_ns_ = 0;
  std::uint32_t divider_ = 0;
  std::int64_t time_ns_ = 0;
  std::uint64_t data_frames_ = 0;
  std::uint64_t requests_rejected_ = 0;
  std::uint32_t corrupt_bit_ = 0;

  std::array<EncoderEmulator, kChannels> emulators_{};
  std::array<PulseSegment, kChannels> period_scratch_{};
  EncoderLineReader lines_{};
  std::array<std::int32_t, kChannels> pwm_values_{};
  std::array<std::int32_t, kChannels> counts_{};
  std::array<bool, kChannels> pins_in_{};
  std::array<bool, kChannels> pins_out_{};
  std::array<double, kChannels> duty_scratch_{};
  /// Twin image: the bits of the duties pwm_values_ and pwm_words_ were measured from, with
  /// pins_in_ as they stand while pwm_memo_valid_ (exact memoisation, SampleTwin).
  std::array<std::uint64_t, kChannels> duty_bits_{};
  ChannelWords pwm_words_ = 0;
  bool pwm_memo_valid_ = false;
  FrameBytes answer_register_{};      ///< answer to the latest request; zeros at power-up
  bool answer_register_data_ = false;  ///< it answers a request whose opcode byte is not NOOP
  FrameBytes previous_miso_{};         ///< what the latest transfer shifted out
};

/// The emulated bus: forwards each transfer to a device (not owned).
class EmulatedSpiBus final : public SpiBus {
 public:
  explicit EmulatedSpiBus(SpiDevice& device, const char* name = "mock") noexcept
      : device_(device), name_(name) {}
  BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override {
    device_.Exchange(mosi, miso);
    return {};
  }
  /// Both transfers straight to the device (an emulated transfer cannot fail).
  BusStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                         const FrameBytes& fetch, FrameBytes& answer) noexcept override {
    device_.Exchange(request, request_miso);
    device_.Exchange(fetch, answer);
    return {};
  }
  [[nodiscard]] const char* Name() const noexcept override { return name_; }

 private:
  SpiDevice& device_;
  const char* name_;
};

/// Wires a twin board's encoder emulator to an ECS board's readers in one process: the twin
/// board's periods are kept in a ring; pass the link to the ECS board's SetEncoderSource.
class EmulatorToReaderLink final : public EncoderLineHistory {
 public:
  explicit EmulatorToReaderLink(EmulatedFpga& twin_board) noexcept : twin_(twin_board) {
    twin_.SetEncoderSink(this);
  }
  ~EmulatorToReaderLink() override { twin_.SetEncoderSink(nullptr); }
  EmulatorToReaderLink(const EmulatorToReaderLink&) = delete;
  EmulatorToReaderLink& operator=(const EmulatorToReaderLink&) = delete;

 private:
  EmulatedFpga& twin_;
};

/// Wires an ECS board's PWM generator to a twin board's PWM reader in one process.
class GeneratorToReaderLink final : public PwmSignalSource {
 public:
  explicit GeneratorToReaderLink(const EmulatedFpga& ecs_board) noexcept : ecs_(ecs_board) {}
  void DutyAt(std::int64_t t_ns, std::array<double, kChannels>& duty_out) noexcept override;

 private:
  const EmulatedFpga& ecs_;
};

}  // namespace hiltwin::io
