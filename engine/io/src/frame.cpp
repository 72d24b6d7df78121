#include "hiltwin/io/frame.h"

namespace hiltwin::io {
namespace {

// Table-driven CRC, built at compile time so the codec has no start-up step.
constexpr std::array<std::uint8_t, 256> MakeCrcTable() noexcept {
  std::array<std::uint8_t, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    unsigned crc = i;
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80U) != 0 ? ((crc << 1U) ^ 0x2FU) : (crc << 1U);
    }
    table[i] = static_cast<std::uint8_t>(crc & 0xFFU);
  }
  return table;
}
constexpr std::array<std::uint8_t, 256> kCrcTable = MakeCrcTable();

constexpr std::size_t kPayloadOffset = 2;
constexpr std::size_t kStatusOffset = 10;
constexpr std::size_t kCrcOffset = 11;

void PutU16(FrameBytes& out, std::size_t offset, std::uint16_t value) noexcept {
  out[offset] = static_cast<std::uint8_t>(value >> 8U);
  out[offset + 1] = static_cast<std::uint8_t>(value & 0xFFU);
}
std::uint16_t GetU16(const FrameBytes& in, std::size_t offset) noexcept {
  return static_cast<std::uint16_t>((unsigned{in[offset]} << 8U) | unsigned{in[offset + 1]});
}
void PutU32(FrameBytes& out, std::size_t offset, std::uint32_t value) noexcept {
  out[offset] = static_cast<std::uint8_t>(value >> 24U);
  out[offset + 1] = static_cast<std::uint8_t>((value >> 16U) & 0xFFU);
  out[offset + 2] = static_cast<std::uint8_t>((value >> 8U) & 0xFFU);
  out[offset + 3] = static_cast<std::uint8_t>(value & 0xFFU);
}
std::uint32_t GetU32(const FrameBytes& in, std::size_t offset) noexcept {
  return (std::uint32_t{in[offset]} << 24U) | (std::uint32_t{in[offset + 1]} << 16U) |
         (std::uint32_t{in[offset + 2]} << 8U) | std::uint32_t{in[offset + 3]};
}

bool IsPerChannel(Opcode opcode) noexcept {
  const auto v = static_cast<unsigned>(opcode);
  return v >= 4 && v <= 11;
}
std::size_t ChannelOf(Opcode opcode) noexcept { return static_cast<std::size_t>(opcode) & 3U; }

constexpr std::uint16_t kPwmNegativeBit = 0x8000;
constexpr std::uint16_t kPinBit = 0x4000;
constexpr std::uint16_t kValueMask = 0x3FFF;
constexpr std::uint16_t kEncReservedBit = 0x8000;

}  // namespace

const char* ToString(Opcode opcode) noexcept {
  switch (opcode) {
    case Opcode::kNoop: return "NOOP";
    case Opcode::kInit: return "INIT";
    case Opcode::kReset: return "RESET";
    case Opcode::kAll: return "ALL";
    case Opcode::kPwm0: return "PWM0";
    case Opcode::kPwm1: return "PWM1";
    case Opcode::kPwm2: return "PWM2";
    case Opcode::kPwm3: return "PWM3";
    case Opcode::kEnc0: return "ENC0";
    case Opcode::kEnc1: return "ENC1";
    case Opcode::kEnc2: return "ENC2";
    case Opcode::kEnc3: return "ENC3";
    case Opcode::kTest: return "TEST";
  }
  return "?";
}

const char* ToString(Image image) noexcept {
  return image == Image::kIcoboard ? "icoboard" : "icoboard_inverse";
}

std::optional<Image> ParseImage(std::string_view text) noexcept {
  if (text == "icoboard") return Image::kIcoboard;
  if (text == "icoboard_inverse") return Image::kIcoboardInverse;
  return std::nullopt;
}

std::optional<Image> ImageOfIdentity(std::uint8_t identity) noexcept {
  if (identity == kIdentityIcoboard) return Image::kIcoboard;
  if (identity == kIdentityIcoboardInverse) return Image::kIcoboardInverse;
  return std::nullopt;
}

const char* ToString(FrameError error) noexcept {
  switch (error) {
    case FrameError::kOk: return "ok";
    case FrameError::kChecksum: return "checksum mismatch";
    case FrameError::kOpcode: return "unknown opcode";
    case FrameError::kReservedBits: return "reserved bits set";
    case FrameError::kOutOfRange: return "field out of range";
  }
  return "?";
}

Payload PayloadOf(Opcode opcode, Direction direction, Image host_image) noexcept {
  switch (opcode) {
    case Opcode::kNoop:
    case Opcode::kReset: return Payload::kNone;
    case Opcode::kInit:
      return direction == Direction::kRequest ? Payload::kInitRequest : Payload::kInitAnswer;
    case Opcode::kAll: {
      // The ECS host writes PWM and reads encoders; the twin host the reverse (thesis §4.2.1).
      const bool host_writes_pwm = host_image == Image::kIcoboard;
      const bool pwm = (direction == Direction::kRequest) == host_writes_pwm;
      return pwm ? Payload::kPwm : Payload::kEnc;
    }
    case Opcode::kTest: return Payload::kRaw;
    default: break;
  }
  return static_cast<unsigned>(opcode) < 8 ? Payload::kPwm : Payload::kEnc;
}

std::uint8_t Crc8(const std::uint8_t* data, std::size_t size) noexcept {
  std::uint8_t crc = 0xFF;
  for (std::size_t i = 0; i < size; ++i) crc = kCrcTable[static_cast<std::uint8_t>(crc ^ data[i])];
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

std::uint16_t PackPwm(const PwmWord& word) noexcept {
  return static_cast<std::uint16_t>((word.negative ? kPwmNegativeBit : 0U) |
                                    (word.pin ? kPinBit : 0U) | (word.magnitude & kValueMask));
}
std::uint16_t PackEnc(const EncWord& word) noexcept {
  return static_cast<std::uint16_t>((word.pin ? kPinBit : 0U) |
                                    (static_cast<std::uint16_t>(word.counts) & kValueMask));
}
PwmWord UnpackPwm(std::uint16_t bits) noexcept {
  return PwmWord{static_cast<std::uint16_t>(bits & kValueMask), (bits & kPwmNegativeBit) != 0,
                 (bits & kPinBit) != 0};
}
EncWord UnpackEnc(std::uint16_t bits) noexcept {
  int value = bits & kValueMask;
  if ((value & 0x2000) != 0) value -= 0x4000;  // sign-extend the 14-bit field
  return EncWord{static_cast<std::int16_t>(value), (bits & kPinBit) != 0};
}

FrameError Encode(const Frame& frame, Direction direction, Image host_image,
                  FrameBytes& out) noexcept {
  if (static_cast<unsigned>(frame.opcode) > static_cast<unsigned>(Opcode::kTest)) {
    return FrameError::kOpcode;
  }
  out.fill(0);
  out[0] = static_cast<std::uint8_t>(frame.opcode);
  out[1] = frame.sequence;
  if (direction == Direction::kAnswer) {
    if ((frame.status & ~kStatusMask) != 0) return FrameError::kReservedBits;
    out[kStatusOffset] = frame.status;
  }
  const Payload payload = PayloadOf(frame.opcode, direction, host_image);
  const bool single = IsPerChannel(frame.opcode);
  const std::size_t only = ChannelOf(frame.opcode);
  for (std::size_t c = 0; c < kChannels; ++c) {
    if (single && c != only) continue;
    const std::size_t offset = kPayloadOffset + 2 * c;
    if (payload == Payload::kPwm) {
      if (frame.pwm[c].magnitude > kPwmMagnitudeMax) return FrameError::kOutOfRange;
      PutU16(out, offset, PackPwm(frame.pwm[c]));
    } else if (payload == Payload::kEnc) {
      if (frame.enc[c].counts < kEncoderFieldMin || frame.enc[c].counts > kEncoderFieldMax) {
        return FrameError::kOutOfRange;
      }
      PutU16(out, offset, PackEnc(frame.enc[c]));
    }
  }
  if (payload == Payload::kInitRequest) {
    PutU32(out, 2, frame.init_request.step_ns);
    PutU32(out, 6, frame.init_request.clock_divider);
  } else if (payload == Payload::kInitAnswer) {
    out[2] = frame.init_answer.protocol_version;
    out[3] = frame.init_answer.channels;
    out[4] = frame.init_answer.identity;
    PutU32(out, 6, frame.init_answer.clock_divider);
  } else if (payload == Payload::kRaw) {
    for (std::size_t i = 0; i < frame.raw.size(); ++i) out[kPayloadOffset + i] = frame.raw[i];
  }
  out[kCrcOffset] = Crc8(out.data(), kCrcOffset);
  return FrameError::kOk;
}

FrameError Decode(const FrameBytes& in, Direction direction, Image host_image,
                  Frame& out) noexcept {
  if (Crc8(in.data(), kCrcOffset) != in[kCrcOffset]) return FrameError::kChecksum;
  if (in[0] > static_cast<std::uint8_t>(Opcode::kTest)) return FrameError::kOpcode;
  const auto opcode = static_cast<Opcode>(in[0]);
  const std::uint8_t status = in[kStatusOffset];
  if (direction == Direction::kRequest ? status != 0 : (status & ~kStatusMask) != 0) {
    return FrameError::kReservedBits;
  }
  const Payload payload = PayloadOf(opcode, direction, host_image);
  const bool single = IsPerChannel(opcode);
  const std::size_t only = ChannelOf(opcode);

  // Validate everything before writing `out`, so a refused frame changes nothing.
  switch (payload) {
    case Payload::kNone:
      for (std::size_t i = kPayloadOffset; i < kStatusOffset; ++i) {
        if (in[i] != 0) return FrameError::kReservedBits;
      }
      break;
    case Payload::kPwm:
    case Payload::kEnc:
      for (std::size_t c = 0; c < kChannels; ++c) {
        const std::uint16_t bits = GetU16(in, kPayloadOffset + 2 * c);
        if (single && c != only) {
          if (bits != 0) return FrameError::kReservedBits;
        } else if (payload == Payload::kPwm) {
          if ((bits & kValueMask) > kPwmMagnitudeMax) return FrameError::kOutOfRange;
        } else if ((bits & kEncReservedBit) != 0) {
          return FrameError::kReservedBits;
        }
      }
      break;
    case Payload::kInitAnswer:
      if (in[5] != 0) return FrameError::kReservedBits;
      break;
    case Payload::kInitRequest:
    case Payload::kRaw: break;
  }

  out.opcode = opcode;
  out.sequence = in[1];
  out.status = status;
  switch (payload) {
    case Payload::kPwm:
    case Payload::kEnc:
      for (std::size_t c = 0; c < kChannels; ++c) {
        if (single && c != only) continue;
        const std::uint16_t bits = GetU16(in, kPayloadOffset + 2 * c);
        if (payload == Payload::kPwm) {
          out.pwm[c] = UnpackPwm(bits);
        } else {
          out.enc[c] = UnpackEnc(bits);
        }
      }
      break;
    case Payload::kInitRequest:
      out.init_request = InitRequest{GetU32(in, 2), GetU32(in, 6)};
      break;
    case Payload::kInitAnswer:
      out.init_answer = InitAnswer{in[2], in[3], in[4], GetU32(in, 6)};
      break;
    case Payload::kRaw:
      for (std::size_t i = 0; i < out.raw.size(); ++i) out.raw[i] = in[kPayloadOffset + i];
      break;
    case Payload::kNone: break;
  }
  return FrameError::kOk;
}

}  // namespace hiltwin::io
