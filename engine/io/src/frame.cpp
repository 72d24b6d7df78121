#include "hiltwin/io/frame.h"

#include <bit>
#include <cstring>
#include <utility>

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
constexpr std::size_t kPayloadBytes = 8;
constexpr std::size_t kStatusOffset = 10;
constexpr std::size_t kCrcOffset = 11;

// The CRC is affine in the message: the CRC of bytes 0..10 is the CRC of eleven zero bytes XOR,
// per byte, what that byte contributes from its position (the table applied once per byte that
// follows it). One table per position (2.8 kB) turns a frame's CRC into eleven independent
// lookups, without the chain of the bytewise loop (an exchange codes seven frames).
struct FrameCrcTables {
  std::array<std::array<std::uint8_t, 256>, kCrcOffset> at{};
  std::uint8_t of_zeros = 0;
};
constexpr FrameCrcTables MakeFrameCrcTables() noexcept {
  FrameCrcTables tables;
  for (std::size_t position = 0; position < kCrcOffset; ++position) {
    for (unsigned value = 0; value < 256; ++value) {
      std::uint8_t reg = kCrcTable[value];
      for (std::size_t next = position + 1; next < kCrcOffset; ++next) reg = kCrcTable[reg];
      tables.at[position][value] = reg;
    }
  }
  std::uint8_t crc = 0xFF;
  for (std::size_t i = 0; i < kCrcOffset; ++i) crc = kCrcTable[crc];
  tables.of_zeros = static_cast<std::uint8_t>(crc ^ 0xFFU);
  return tables;
}
constexpr FrameCrcTables kFrameCrc = MakeFrameCrcTables();

template <std::size_t... kPositions>
std::uint8_t FrameCrcOf(const FrameBytes& bytes, std::index_sequence<kPositions...>) noexcept {
  return static_cast<std::uint8_t>(kFrameCrc.of_zeros ^
                                   (kFrameCrc.at[kPositions][bytes[kPositions]] ^ ...));
}
/// Crc8(bytes.data(), 11), unrolled.
std::uint8_t FrameCrc(const FrameBytes& bytes) noexcept {
  return FrameCrcOf(bytes, std::make_index_sequence<kCrcOffset>{});
}
/// FrameCrc of a frame whose bytes 2..9 are zero (NOOP, RESET: the fetch and its answer, two of
/// the seven frames an exchange codes): only bytes 0, 1 and 10 contribute.
std::uint8_t EmptyFrameCrc(const FrameBytes& bytes) noexcept {
  return static_cast<std::uint8_t>(kFrameCrc.of_zeros ^ kFrameCrc.at[0][bytes[0]] ^
                                   kFrameCrc.at[1][bytes[1]] ^
                                   kFrameCrc.at[kStatusOffset][bytes[kStatusOffset]]);
}

// What bytes 2..9 hold, per opcode, direction and host image: decided by a lookup, not by
// branches per frame.
constexpr std::size_t PayloadIndex(unsigned op, Direction direction, Image image) noexcept {
  return std::size_t{op} * 4 + static_cast<std::size_t>(direction) * 2 +
         static_cast<std::size_t>(image);
}
constexpr Payload PayloadRule(unsigned op, Direction direction, Image host_image) noexcept {
  switch (static_cast<Opcode>(op)) {
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
  return op < 8 ? Payload::kPwm : Payload::kEnc;
}
constexpr std::size_t kOpcodes = static_cast<std::size_t>(Opcode::kTest) + 1;
constexpr std::array<Payload, kOpcodes * 4> MakePayloads() noexcept {
  std::array<Payload, kOpcodes * 4> table{};
  for (unsigned op = 0; op < kOpcodes; ++op) {
    for (const Direction direction : {Direction::kRequest, Direction::kAnswer}) {
      for (const Image image : {Image::kIcoboard, Image::kIcoboardInverse}) {
        table[PayloadIndex(op, direction, image)] = PayloadRule(op, direction, image);
      }
    }
  }
  return table;
}
constexpr std::array<Payload, kOpcodes * 4> kPayloads = MakePayloads();

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

// Word-wide packing: the four channel words (bytes 2..9, big-endian) as one 64-bit body, the
// word of channel c in bits 63-16c..48-16c. The compilers turn these two into one load or store
// and a byte swap.
inline std::uint64_t GetBody(const FrameBytes& in) noexcept {
  return (std::uint64_t{GetU32(in, kPayloadOffset)} << 32U) | GetU32(in, kPayloadOffset + 4);
}
inline void PutBody(FrameBytes& out, std::uint64_t body) noexcept {
  PutU32(out, kPayloadOffset, static_cast<std::uint32_t>(body >> 32U));
  PutU32(out, kPayloadOffset + 4, static_cast<std::uint32_t>(body & 0xFFFF'FFFFU));
}
constexpr unsigned LaneShift(std::size_t c) noexcept { return static_cast<unsigned>(48 - 16 * c); }
constexpr std::uint64_t Lane(std::size_t c, std::uint64_t word) noexcept {
  return word << LaneShift(c);
}
std::uint16_t WordOf(std::uint64_t body, std::size_t c) noexcept {
  return static_cast<std::uint16_t>((body >> LaneShift(c)) & 0xFFFFU);
}
/// Replicates a 16-bit pattern into the four lanes.
constexpr std::uint64_t AllLanes(std::uint16_t word) noexcept {
  return std::uint64_t{word} * 0x0001'0001'0001'0001ULL;
}

// The channel words an opcode carries, as lanes of the body: all four for ALL, one for
// PWMc/ENCc (the other words are zero on the wire).
constexpr std::array<std::uint64_t, kOpcodes> MakeCarriedLanes() noexcept {
  std::array<std::uint64_t, kOpcodes> lanes{};
  lanes[static_cast<std::size_t>(Opcode::kAll)] = ~std::uint64_t{0};
  for (std::size_t c = 0; c < kChannels; ++c) {
    lanes[static_cast<std::size_t>(PwmOpcode(c))] = Lane(c, 0xFFFFU);
    lanes[static_cast<std::size_t>(EncOpcode(c))] = Lane(c, 0xFFFFU);
  }
  return lanes;
}
constexpr std::array<std::uint64_t, kOpcodes> kCarriedLanes = MakeCarriedLanes();

/// Calls f(std::integral_constant<c>) for each channel, unrolled: the per-cycle frame's four
/// words without a loop counter.
template <typename F, std::size_t... kC>
void EachChannel(F&& f, std::index_sequence<kC...> /*channels*/) noexcept {
  (f(std::integral_constant<std::size_t, kC>{}), ...);
}
template <typename F>
void ForEachChannel(F&& f) noexcept {
  EachChannel(f, std::make_index_sequence<kChannels>{});
}

constexpr std::uint16_t kValueMask = kWordValueMask;
constexpr std::uint16_t kEncReservedBit = kWordBit15;

// The channel words of a frame: all four are packed and checked without a branch per field, the
// lanes the opcode does not carry then cleared; false when a carried field does not fit its bits.
bool PutPwmWords(const Frame& frame, std::uint64_t carried, FrameBytes& out) noexcept {
  std::uint64_t body = 0;
  std::uint64_t out_of_range = 0;
  ForEachChannel([&](auto c) {
    body |= Lane(c, PackPwm(frame.pwm[c]));
    out_of_range |= Lane(c, unsigned{frame.pwm[c].magnitude > kPwmMagnitudeMax});
  });
  PutBody(out, body & carried);
  return (out_of_range & carried) == 0;
}
bool PutEncWords(const Frame& frame, std::uint64_t carried, FrameBytes& out) noexcept {
  constexpr auto kSpan = static_cast<unsigned>(kEncoderFieldMax - kEncoderFieldMin);
  std::uint64_t body = 0;
  std::uint64_t out_of_range = 0;
  ForEachChannel([&](auto c) {
    body |= Lane(c, PackEnc(frame.enc[c]));
    const auto offset = static_cast<unsigned>(frame.enc[c].counts - kEncoderFieldMin);
    out_of_range |= Lane(c, unsigned{offset > kSpan});
  });
  PutBody(out, body & carried);
  return (out_of_range & carried) == 0;
}

// A word of a channel the opcode does not carry must be zero (reserved). A frame is checked in
// channel order, so of several failing words the first (the highest lane) names the error.
FrameError CheckPwmWords(std::uint64_t body, std::uint64_t carried) noexcept {
  const std::uint64_t reserved = body & ~carried;
  // A 14-bit magnitude above 2048 carries into bit 15 of its lane when 0x8000 - 2049 is added.
  constexpr auto kMagnitudeCarry = static_cast<std::uint16_t>(0x8000U - kPwmMagnitudeMax - 1U);
  const std::uint64_t magnitudes = body & AllLanes(kValueMask);
  const std::uint64_t out_of_range =
      (magnitudes + AllLanes(kMagnitudeCarry)) & AllLanes(0x8000U) & carried;
  const std::uint64_t failing = reserved | out_of_range;
  if (failing == 0) return FrameError::kOk;
  const std::uint64_t first = std::uint64_t{1} << (63 - std::countl_zero(failing));
  return (reserved & first) != 0 ? FrameError::kReservedBits : FrameError::kOutOfRange;
}
FrameError CheckEncWords(std::uint64_t body, std::uint64_t carried) noexcept {
  const std::uint64_t allowed = carried & ~AllLanes(kEncReservedBit);
  return (body & ~allowed) == 0 ? FrameError::kOk : FrameError::kReservedBits;
}
FrameError CheckWords(std::uint64_t body, Payload payload, std::uint64_t carried) noexcept {
  return payload == Payload::kPwm ? CheckPwmWords(body, carried) : CheckEncWords(body, carried);
}
FrameError CheckPayload(const FrameBytes& in, Payload payload, std::uint64_t carried) noexcept {
  switch (payload) {
    case Payload::kNone: return GetBody(in) == 0 ? FrameError::kOk : FrameError::kReservedBits;
    case Payload::kPwm: return CheckPwmWords(GetBody(in), carried);
    case Payload::kEnc: return CheckEncWords(GetBody(in), carried);
    case Payload::kInitAnswer: return in[5] == 0 ? FrameError::kOk : FrameError::kReservedBits;
    case Payload::kInitRequest:
    case Payload::kRaw: break;
  }
  return FrameError::kOk;
}

/// What every frame is checked for first, in this order: CRC, opcode, status byte. `body` is
/// GetBody(in).
inline FrameError CheckHeader(const FrameBytes& in, std::uint64_t body,
                              Direction direction) noexcept {
  const std::uint8_t crc = body == 0 ? EmptyFrameCrc(in) : FrameCrc(in);
  if (crc != in[kCrcOffset]) return FrameError::kChecksum;
  if (in[0] > static_cast<std::uint8_t>(Opcode::kTest)) return FrameError::kOpcode;
  const std::uint8_t status = in[kStatusOffset];
  if (direction == Direction::kRequest ? status != 0 : (status & ~kStatusMask) != 0) {
    return FrameError::kReservedBits;
  }
  return FrameError::kOk;
}

/// Bytes 0, 1, 10 and 11 around a payload already in place.
void PutHeader(unsigned op, std::uint8_t sequence, std::uint8_t answer_status, bool empty_body,
               FrameBytes& out) noexcept {
  out[0] = static_cast<std::uint8_t>(op);
  out[1] = sequence;
  out[kStatusOffset] = answer_status;
  out[kCrcOffset] = empty_body ? EmptyFrameCrc(out) : FrameCrc(out);
}

// Decoding writes the carried words only: a per-channel frame leaves the other slots as they were.
template <typename Slots, typename Unpack>
void GetWords(const FrameBytes& in, unsigned op, Slots& slots, Unpack unpack) noexcept {
  const std::uint64_t body = GetBody(in);
  if (op == static_cast<unsigned>(Opcode::kAll)) {
    ForEachChannel([&](auto c) { slots[c] = unpack(WordOf(body, c)); });
  } else {
    const std::size_t c = op & 3U;
    slots[c] = unpack(WordOf(body, c));
  }
}

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
  const auto op = static_cast<unsigned>(opcode);
  return op <= static_cast<unsigned>(Opcode::kTest) ? kPayloads[PayloadIndex(op, direction,
                                                                              host_image)]
                                                    : Payload::kEnc;
}

std::uint8_t Crc8(const std::uint8_t* data, std::size_t size) noexcept {
  std::uint8_t crc = 0xFF;
  for (std::size_t i = 0; i < size; ++i) crc = kCrcTable[static_cast<std::uint8_t>(crc ^ data[i])];
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

FrameError Encode(const Frame& frame, Direction direction, Image host_image,
                  FrameBytes& out) noexcept {
  const auto op = static_cast<unsigned>(frame.opcode);
  if (op > static_cast<unsigned>(Opcode::kTest)) return FrameError::kOpcode;
  const bool answer = direction == Direction::kAnswer;
  if (answer && (frame.status & ~kStatusMask) != 0) return FrameError::kReservedBits;
  // Every byte is written exactly once: no clearing pass before the fields.
  const Payload payload = kPayloads[PayloadIndex(op, direction, host_image)];
  switch (payload) {
    case Payload::kPwm:
      if (!PutPwmWords(frame, kCarriedLanes[op], out)) return FrameError::kOutOfRange;
      break;
    case Payload::kEnc:
      if (!PutEncWords(frame, kCarriedLanes[op], out)) return FrameError::kOutOfRange;
      break;
    case Payload::kInitRequest:
      PutU32(out, 2, frame.init_request.step_ns);
      PutU32(out, 6, frame.init_request.clock_divider);
      break;
    case Payload::kInitAnswer:
      out[2] = frame.init_answer.protocol_version;
      out[3] = frame.init_answer.channels;
      out[4] = frame.init_answer.identity;
      out[5] = 0;
      PutU32(out, 6, frame.init_answer.clock_divider);
      break;
    case Payload::kRaw: std::memcpy(&out[kPayloadOffset], frame.raw.data(), kPayloadBytes); break;
    case Payload::kNone: std::memset(&out[kPayloadOffset], 0, kPayloadBytes); break;
  }
  PutHeader(op, frame.sequence, answer ? frame.status : std::uint8_t{0},
            payload == Payload::kNone, out);
  return FrameError::kOk;
}

FrameError Decode(const FrameBytes& in, Direction direction, Image host_image,
                  Frame& out) noexcept {
  const FrameError header = CheckHeader(in, GetBody(in), direction);
  if (header != FrameError::kOk) return header;
  const unsigned op = in[0];
  const std::uint8_t status = in[kStatusOffset];
  const Payload payload = kPayloads[PayloadIndex(op, direction, host_image)];
  // Validate everything before writing `out`, so a refused frame changes nothing.
  const FrameError error = CheckPayload(in, payload, kCarriedLanes[op]);
  if (error != FrameError::kOk) return error;

  out.opcode = static_cast<Opcode>(op);
  out.sequence = in[1];
  out.status = status;
  switch (payload) {
    case Payload::kPwm:
      GetWords(in, op, out.pwm, [](auto word) { return UnpackPwm(word); });
      break;
    case Payload::kEnc:
      GetWords(in, op, out.enc, [](auto word) { return UnpackEnc(word); });
      break;
    case Payload::kInitRequest:
      out.init_request = InitRequest{GetU32(in, 2), GetU32(in, 6)};
      break;
    case Payload::kInitAnswer:
      out.init_answer = InitAnswer{in[2], in[3], in[4], GetU32(in, 6)};
      break;
    case Payload::kRaw: std::memcpy(out.raw.data(), &in[kPayloadOffset], kPayloadBytes); break;
    case Payload::kNone: break;
  }
  return FrameError::kOk;
}

void EncodeNoop(std::uint8_t sequence, std::uint8_t status, FrameBytes& out) noexcept {
  // What Encode writes for a NOOP (Payload::kNone): zeros but for bytes 1, 10 and the CRC.
  out = FrameBytes{};
  out[1] = sequence;
  out[kStatusOffset] = status;
  out[kCrcOffset] = EmptyFrameCrc(out);
}

bool IsNoopRequest(const FrameBytes& in) noexcept {
  // Decode's checks for a NOOP request: CRC, status byte 0, bytes 2..9 zero (reserved).
  return in[0] == static_cast<std::uint8_t>(Opcode::kNoop) && in[kStatusOffset] == 0 &&
         GetBody(in) == 0 && EmptyFrameCrc(in) == in[kCrcOffset];
}

constexpr auto kAllOpcode = static_cast<unsigned>(Opcode::kAll);

FrameError EncodeAll(const AllFrame& frame, Direction direction, Image host_image,
                     FrameBytes& out) noexcept {
  const bool answer = direction == Direction::kAnswer;
  if (answer && (frame.status & ~kStatusMask) != 0) return FrameError::kReservedBits;
  const Payload payload = kPayloads[PayloadIndex(kAllOpcode, direction, host_image)];
  const FrameError error = CheckWords(frame.words, payload, kCarriedLanes[kAllOpcode]);
  if (error != FrameError::kOk) return error;
  PutBody(out, frame.words);
  PutHeader(kAllOpcode, frame.sequence, answer ? frame.status : std::uint8_t{0}, false, out);
  return FrameError::kOk;
}

FrameError DecodeAll(const FrameBytes& in, Direction direction, Image host_image,
                     AllFrame& out) noexcept {
  const std::uint64_t words = GetBody(in);
  const FrameError header = CheckHeader(in, words, direction);
  if (header != FrameError::kOk) return header;
  if (in[0] != kAllOpcode) return FrameError::kOpcode;
  const Payload payload = kPayloads[PayloadIndex(kAllOpcode, direction, host_image)];
  const FrameError error = CheckWords(words, payload, kCarriedLanes[kAllOpcode]);
  if (error != FrameError::kOk) return error;
  out = AllFrame{in[1], in[kStatusOffset], words};
  return FrameError::kOk;
}

}  // namespace hiltwin::io
