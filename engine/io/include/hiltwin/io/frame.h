#pragma once
/// The IcoBoard SPI frame codec: 12-byte full-duplex frames, CRC-8 protected. Pure logic, no OS
/// calls. docs/spi-protocol.md is the single source of truth for the byte layout; the tests
/// parse that document's worked frames and compare them with what this codec produces.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace hiltwin::io {

/// Bytes per SPI transfer, both directions (MOSI request and MISO answer).
constexpr std::size_t kFrameBytes = 12;
/// PWM and encoder channels per board.
constexpr std::size_t kChannels = 4;
/// One frame on the wire.
using FrameBytes = std::array<std::uint8_t, kFrameBytes>;

/// Byte 0 of every frame. Values above kTest are invalid.
enum class Opcode : std::uint8_t {
  kNoop = 0,
  kInit = 1,
  kReset = 2,
  kAll = 3,
  kPwm0 = 4,
  kPwm1 = 5,
  kPwm2 = 6,
  kPwm3 = 7,
  kEnc0 = 8,
  kEnc1 = 9,
  kEnc2 = 10,
  kEnc3 = 11,
  kTest = 12,
};
[[nodiscard]] const char* ToString(Opcode opcode) noexcept;
/// PWM opcode of channel `c` (0..3).
[[nodiscard]] constexpr Opcode PwmOpcode(std::size_t c) noexcept {
  return static_cast<Opcode>(4 + (c & 3U));
}
/// ENC opcode of channel `c` (0..3).
[[nodiscard]] constexpr Opcode EncOpcode(std::size_t c) noexcept {
  return static_cast<Opcode>(8 + (c & 3U));
}

/// The two FPGA images (thesis §4.2.3).
enum class Image : std::uint8_t {
  kIcoboard,         ///< ECS side: PWM out, encoder counts in
  kIcoboardInverse,  ///< twin side: encoder positions out, PWM in
};
/// "icoboard" / "icoboard_inverse".
[[nodiscard]] const char* ToString(Image image) noexcept;
/// Parses "icoboard" / "icoboard_inverse"; nullopt otherwise.
[[nodiscard]] std::optional<Image> ParseImage(std::string_view text) noexcept;
/// The image on the other end of the HiL loop.
[[nodiscard]] constexpr Image Counterpart(Image image) noexcept {
  return image == Image::kIcoboard ? Image::kIcoboardInverse : Image::kIcoboard;
}

/// INIT answer byte 4: the ECS image answers 11 as in the seed framework.
constexpr std::uint8_t kIdentityIcoboard = 11;
/// INIT answer byte 4 of the twin image.
constexpr std::uint8_t kIdentityIcoboardInverse = 22;
/// Identity byte of an image.
[[nodiscard]] constexpr std::uint8_t IdentityOf(Image image) noexcept {
  return image == Image::kIcoboard ? kIdentityIcoboard : kIdentityIcoboardInverse;
}
/// Image of an identity byte; nullopt for an unknown value.
[[nodiscard]] std::optional<Image> ImageOfIdentity(std::uint8_t identity) noexcept;

/// Protocol version answered by INIT (byte 2).
constexpr std::uint8_t kProtocolVersion = 1;

/// Which way a frame travels; the payload's meaning depends on it.
enum class Direction : std::uint8_t {
  kRequest,  ///< host -> board (MOSI)
  kAnswer,   ///< board -> host (MISO)
};

/// Answer status bits (byte 10 of a MISO frame). Requests carry 0 there.
constexpr std::uint8_t kStatusInitialised = 0x01;     ///< INIT accepted, data frames served
constexpr std::uint8_t kStatusRequestRejected = 0x02; ///< the last request failed the board's checks
constexpr std::uint8_t kStatusPulseLimit = 0x04;      ///< encoder emulator could not emit all pulses
constexpr std::uint8_t kStatusInitRejected = 0x08;    ///< INIT parameters out of range
constexpr std::uint8_t kStatusMask = 0x0F;

/// Largest PWM magnitude a frame may carry: the PWM resolution (duty 1.0).
constexpr std::uint16_t kPwmMagnitudeMax = 2048;
/// Encoder field: 14-bit two's complement, [-8192, 8191].
constexpr std::int32_t kEncoderFieldMin = -8192;
constexpr std::int32_t kEncoderFieldMax = 8191;

/// One PWM channel word: bit 15 direction (1 = negative), bit 14 digital pin, bits 13..0 magnitude.
struct PwmWord {
  std::uint16_t magnitude = 0;  ///< 0..kPwmMagnitudeMax
  bool negative = false;
  bool pin = false;
  friend bool operator==(const PwmWord&, const PwmWord&) = default;
};

/// One encoder channel word: bit 15 reserved (0), bit 14 digital pin, bits 13..0 counts.
struct EncWord {
  std::int16_t counts = 0;  ///< relative position, [kEncoderFieldMin, kEncoderFieldMax]
  bool pin = false;
  friend bool operator==(const EncWord&, const EncWord&) = default;
};

/// INIT request payload (thesis §4.2.2: the step size travels in INIT's spare bytes).
struct InitRequest {
  std::uint32_t step_ns = 0;        ///< the twin's time step (the ECS's period for icoboard)
  std::uint32_t clock_divider = 0;  ///< encoder emulator divider of the 100 MHz clock
  friend bool operator==(const InitRequest&, const InitRequest&) = default;
};

/// INIT answer payload.
struct InitAnswer {
  std::uint8_t protocol_version = kProtocolVersion;
  std::uint8_t channels = kChannels;
  std::uint8_t identity = 0;        ///< kIdentityIcoboard or kIdentityIcoboardInverse
  std::uint32_t clock_divider = 0;  ///< divider the board accepted (0 for icoboard)
  friend bool operator==(const InitAnswer&, const InitAnswer&) = default;
};

/// What a frame's bytes 2..9 hold, decided by opcode, direction and the host's image.
enum class Payload : std::uint8_t { kNone, kPwm, kEnc, kInitRequest, kInitAnswer, kRaw };
[[nodiscard]] Payload PayloadOf(Opcode opcode, Direction direction, Image host_image) noexcept;

/// A decoded frame. Only the fields named by PayloadOf() are meaningful; for per-channel opcodes
/// only that channel's word is (the other slots are zero on the wire).
struct Frame {
  Opcode opcode = Opcode::kNoop;
  std::uint8_t sequence = 0;  ///< byte 1: set by the host, echoed by the board
  std::uint8_t status = 0;    ///< byte 10: kStatus* bits in answers, 0 in requests
  std::array<PwmWord, kChannels> pwm{};
  std::array<EncWord, kChannels> enc{};
  std::array<std::uint8_t, 8> raw{};  ///< TEST payload, echoed verbatim
  InitRequest init_request{};
  InitAnswer init_answer{};
};

/// Why a frame was refused; kOk when it was accepted.
enum class FrameError : std::uint8_t {
  kOk,
  kChecksum,       ///< CRC-8 over bytes 0..10 does not match byte 11
  kOpcode,         ///< byte 0 is not an opcode
  kReservedBits,   ///< a reserved bit or byte is not zero
  kOutOfRange,     ///< a field is outside its range (PWM magnitude > 2048, INIT answer fields)
};
[[nodiscard]] const char* ToString(FrameError error) noexcept;

/// CRC-8/AUTOSAR (poly 0x2F, init 0xFF, xorout 0xFF, no reflection). Check("123456789") = 0xDF.
[[nodiscard]] std::uint8_t Crc8(const std::uint8_t* data, std::size_t size) noexcept;

/// Encodes `frame` into `out` (CRC included). Returns kOutOfRange, and leaves `out` unspecified,
/// when a field does not fit its bits. Never allocates.
[[nodiscard]] FrameError Encode(const Frame& frame, Direction direction, Image host_image,
                                FrameBytes& out) noexcept;

/// Decodes and validates `in`. On any error `out` is left untouched, so callers hold their
/// previous values. Never allocates; accepts exactly what Encode can produce.
[[nodiscard]] FrameError Decode(const FrameBytes& in, Direction direction, Image host_image,
                                Frame& out) noexcept;

/// Encode() of the NOOP frame numbered `sequence` with status byte `status` (0 in requests;
/// kStatusMask bits only), from the CRC tables directly: the driver's fetch and the board's
/// answer to it, in every exchange. Cannot fail.
void EncodeNoop(std::uint8_t sequence, std::uint8_t status, FrameBytes& out) noexcept;
/// True exactly when Decode(in, Direction::kRequest, any image) accepts `in` as a NOOP: the
/// bytes EncodeNoop(in[1], 0) writes.
[[nodiscard]] bool IsNoopRequest(const FrameBytes& in) noexcept;

/// The four channel words of a frame (the PackPwm/PackEnc bits) as one value in wire order:
/// channel c's word in bits 63-16c..48-16c, so bytes 2..9 of the frame are its big-endian bytes.
/// Word-wide packing for the per-cycle ALL frames.
using ChannelWords = std::uint64_t;
[[nodiscard]] constexpr std::uint16_t ChannelWord(ChannelWords words, std::size_t c) noexcept {
  return static_cast<std::uint16_t>((words >> (48U - 16U * (c & 3U))) & 0xFFFFU);
}
/// `word` as channel c's word (OR the four together).
[[nodiscard]] constexpr ChannelWords PlaceChannelWord(std::size_t c, std::uint16_t word) noexcept {
  return ChannelWords{word} << (48U - 16U * (c & 3U));
}

/// An ALL frame (the per-cycle opcode) without a Frame in between: what its bytes 1..10 hold.
struct AllFrame {
  std::uint8_t sequence = 0;
  std::uint8_t status = 0;  ///< kStatus* bits in answers, 0 in requests
  ChannelWords words = 0;   ///< PWM or encoder words, as PayloadOf(kAll, ...) says
  friend bool operator==(const AllFrame&, const AllFrame&) = default;
};

/// Encode() of the ALL frame `frame`: the same bytes and the same checks as for a Frame with
/// opcode kAll and these words (a word Decode would refuse is refused: kOutOfRange for a PWM
/// magnitude above 2048, kReservedBits for an encoder word with bit 15 set).
[[nodiscard]] FrameError EncodeAll(const AllFrame& frame, Direction direction, Image host_image,
                                   FrameBytes& out) noexcept;
/// Decode() of an ALL frame: the same checks and errors; `out` untouched on any error. A valid
/// frame of another opcode gives kOpcode: call Decode for frames whose byte 0 is not kAll.
[[nodiscard]] FrameError DecodeAll(const FrameBytes& in, Direction direction, Image host_image,
                                   AllFrame& out) noexcept;

/// Channel word bits: PWM direction (1 = negative) or encoder reserved bit, digital pin, value.
constexpr std::uint16_t kWordBit15 = 0x8000;
constexpr std::uint16_t kWordPinBit = 0x4000;
constexpr std::uint16_t kWordValueMask = 0x3FFF;

/// A channel word's fields one by one, as UnpackPwm/UnpackEnc give them, without building the
/// struct (the per-cycle loops): the digital pin; the signed PWM value (PwmValueFromWord of
/// UnpackPwm); the encoder counts, the 14-bit field sign-extended (its bit 13 moved to bit 15,
/// then shifted back arithmetically).
[[nodiscard]] constexpr bool WordPin(std::uint16_t bits) noexcept {
  return (bits & kWordPinBit) != 0;
}
[[nodiscard]] constexpr std::int32_t PwmValueOfWord(std::uint16_t bits) noexcept {
  const std::int32_t magnitude = bits & kWordValueMask;
  return (bits & kWordBit15) != 0 ? -magnitude : magnitude;
}
[[nodiscard]] constexpr std::int16_t EncCountsOfWord(std::uint16_t bits) noexcept {
  const auto high = static_cast<std::int16_t>(static_cast<std::uint16_t>(bits << 2U));
  return static_cast<std::int16_t>(high >> 2);
}

/// Packs/unpacks channel words (exposed for the board model and tests); inline, as the drivers
/// and the board pack four of them per cycle.
[[nodiscard]] inline std::uint16_t PackPwm(const PwmWord& word) noexcept {
  return static_cast<std::uint16_t>((word.negative ? kWordBit15 : 0U) |
                                    (word.pin ? kWordPinBit : 0U) |
                                    (word.magnitude & kWordValueMask));
}
[[nodiscard]] inline std::uint16_t PackEnc(const EncWord& word) noexcept {
  return static_cast<std::uint16_t>((word.pin ? kWordPinBit : 0U) |
                                    (static_cast<std::uint16_t>(word.counts) & kWordValueMask));
}
[[nodiscard]] inline PwmWord UnpackPwm(std::uint16_t bits) noexcept {
  return PwmWord{static_cast<std::uint16_t>(bits & kWordValueMask), (bits & kWordBit15) != 0,
                 (bits & kWordPinBit) != 0};
}
[[nodiscard]] inline EncWord UnpackEnc(std::uint16_t bits) noexcept {
  return EncWord{EncCountsOfWord(bits), WordPin(bits)};
}

}  // namespace hiltwin::io
