// The codec's fast paths against the codec they replaced: the per-position CRC tables, the
// payload table, the word-wide packing and checks (Encode/Decode) and the ALL frames without a
// Frame (EncodeAll/DecodeAll). The reference below is the per-field codec as it was before them,
// with a bitwise CRC; on random frames of every opcode, both directions and both images the
// bytes, the errors and the decoded fields must be the same.
#include <gtest/gtest.h>

#include <random>

#include "hiltwin/io/frame.h"

namespace hiltwin::io {
namespace {

constexpr Image kImages[] = {Image::kIcoboard, Image::kIcoboardInverse};
constexpr Direction kDirections[] = {Direction::kRequest, Direction::kAnswer};

std::uint8_t BitwiseCrc(const FrameBytes& b) {
  unsigned crc = 0xFF;
  for (std::size_t i = 0; i < 11; ++i) {
    crc ^= b[i];
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80U) != 0 ? ((crc << 1U) ^ 0x2FU) & 0xFFU : (crc << 1U) & 0xFFU;
    }
  }
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

// ---- The reference: the per-field codec before the fast paths. ----
Payload RefPayloadOf(unsigned op, Direction direction, Image host_image) {
  if (op == 0 || op == 2) return Payload::kNone;
  if (op == 1) {
    return direction == Direction::kRequest ? Payload::kInitRequest : Payload::kInitAnswer;
  }
  if (op == 3) {
    const bool pwm = (direction == Direction::kRequest) == (host_image == Image::kIcoboard);
    return pwm ? Payload::kPwm : Payload::kEnc;
  }
  if (op == 12) return Payload::kRaw;
  return op < 8 ? Payload::kPwm : Payload::kEnc;
}
void PutU16(FrameBytes& out, std::size_t at, unsigned v) {
  out[at] = static_cast<std::uint8_t>(v >> 8U);
  out[at + 1] = static_cast<std::uint8_t>(v & 0xFFU);
}
void PutU32(FrameBytes& out, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) out[at + i] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
}
std::uint32_t GetU32(const FrameBytes& in, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v = (v << 8U) | in[at + i];
  return v;
}
bool Single(unsigned op) { return op >= 4 && op <= 11; }

FrameError RefEncode(const Frame& frame, Direction direction, Image image, FrameBytes& out) {
  const auto op = static_cast<unsigned>(frame.opcode);
  if (op > 12) return FrameError::kOpcode;
  out.fill(0);
  out[0] = static_cast<std::uint8_t>(op);
  out[1] = frame.sequence;
  if (direction == Direction::kAnswer) {
    if ((frame.status & ~kStatusMask) != 0) return FrameError::kReservedBits;
    out[10] = frame.status;
  }
  const Payload payload = RefPayloadOf(op, direction, image);
  for (std::size_t c = 0; c < kChannels; ++c) {
    if (Single(op) && c != (op & 3U)) continue;
    if (payload == Payload::kPwm) {
      if (frame.pwm[c].magnitude > kPwmMagnitudeMax) return FrameError::kOutOfRange;
      PutU16(out, 2 + 2 * c, PackPwm(frame.pwm[c]));
    } else if (payload == Payload::kEnc) {
      if (frame.enc[c].counts < kEncoderFieldMin || frame.enc[c].counts > kEncoderFieldMax) {
        return FrameError::kOutOfRange;
      }
      PutU16(out, 2 + 2 * c, PackEnc(frame.enc[c]));
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
    for (std::size_t i = 0; i < 8; ++i) out[2 + i] = frame.raw[i];
  }
  out[11] = BitwiseCrc(out);
  return FrameError::kOk;
}

FrameError RefCheck(const FrameBytes& in, Direction direction, Image image) {
  if (BitwiseCrc(in) != in[11]) return FrameError::kChecksum;
  const unsigned op = in[0];
  if (op > 12) return FrameError::kOpcode;
  if (direction == Direction::kRequest ? in[10] != 0 : (in[10] & ~kStatusMask) != 0) {
    return FrameError::kReservedBits;
  }
  const Payload payload = RefPayloadOf(op, direction, image);
  if (payload == Payload::kNone) {
    for (std::size_t i = 2; i < 10; ++i) {
      if (in[i] != 0) return FrameError::kReservedBits;
    }
  } else if (payload == Payload::kPwm || payload == Payload::kEnc) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      const unsigned bits = (unsigned{in[2 + 2 * c]} << 8U) | in[3 + 2 * c];
      if (Single(op) && c != (op & 3U)) {
        if (bits != 0) return FrameError::kReservedBits;
      } else if (payload == Payload::kPwm) {
        if ((bits & 0x3FFFU) > kPwmMagnitudeMax) return FrameError::kOutOfRange;
      } else if ((bits & 0x8000U) != 0) {
        return FrameError::kReservedBits;
      }
    }
  } else if (payload == Payload::kInitAnswer && in[5] != 0) {
    return FrameError::kReservedBits;
  }
  return FrameError::kOk;
}

FrameError RefDecode(const FrameBytes& in, Direction direction, Image image, Frame& out) {
  const FrameError error = RefCheck(in, direction, image);
  if (error != FrameError::kOk) return error;
  const unsigned op = in[0];
  out.opcode = static_cast<Opcode>(op);
  out.sequence = in[1];
  out.status = in[10];
  const Payload payload = RefPayloadOf(op, direction, image);
  for (std::size_t c = 0; c < kChannels; ++c) {
    if (Single(op) && c != (op & 3U)) continue;
    const auto bits = static_cast<std::uint16_t>((unsigned{in[2 + 2 * c]} << 8U) | in[3 + 2 * c]);
    if (payload == Payload::kPwm) out.pwm[c] = UnpackPwm(bits);
    if (payload == Payload::kEnc) out.enc[c] = UnpackEnc(bits);
  }
  if (payload == Payload::kInitRequest) out.init_request = {GetU32(in, 2), GetU32(in, 6)};
  if (payload == Payload::kInitAnswer) out.init_answer = {in[2], in[3], in[4], GetU32(in, 6)};
  if (payload == Payload::kRaw) {
    for (std::size_t i = 0; i < 8; ++i) out.raw[i] = in[2 + i];
  }
  return FrameError::kOk;
}

// ---- Random material. ----
template <typename T>
T Pick(std::mt19937_64& rng, T lo, T hi) {
  return static_cast<T>(std::uniform_int_distribution<long long>(lo, hi)(rng));
}

/// A frame with every field random, some of them beyond their range.
Frame RandomFrame(std::mt19937_64& rng, unsigned op, bool in_range) {
  Frame f;
  f.opcode = static_cast<Opcode>(op);
  f.sequence = Pick<std::uint8_t>(rng, 0, 255);
  f.status = Pick<std::uint8_t>(rng, 0, in_range ? 15 : 255);
  for (std::size_t c = 0; c < kChannels; ++c) {
    f.pwm[c] = PwmWord{Pick<std::uint16_t>(rng, 0, in_range ? 2048 : 0x3FFF),
                       Pick(rng, 0, 1) == 1, Pick(rng, 0, 1) == 1};
    f.enc[c] = EncWord{Pick<std::int16_t>(rng, in_range ? -8192 : -32768, in_range ? 8191 : 32767),
                       Pick(rng, 0, 1) == 1};
  }
  for (auto& b : f.raw) b = Pick<std::uint8_t>(rng, 0, 255);
  f.init_request = {Pick<std::uint32_t>(rng, 0, 0xFFFF'FFFFU),
                    Pick<std::uint32_t>(rng, 0, 0xFFFF'FFFFU)};
  f.init_answer = {Pick<std::uint8_t>(rng, 0, 255), Pick<std::uint8_t>(rng, 0, 255),
                   Pick<std::uint8_t>(rng, 0, 255), Pick<std::uint32_t>(rng, 0, 0xFFFF'FFFFU)};
  return f;
}

/// A frame with one of its 96 bits flipped, and its CRC repaired when `fix_crc`, so the checks
/// past the CRC see it.
FrameBytes Damaged(std::mt19937_64& rng, FrameBytes bytes, bool fix_crc) {
  const auto bit = Pick<unsigned>(rng, 0, fix_crc ? 87 : 95);
  bytes[bit / 8] = static_cast<std::uint8_t>(bytes[bit / 8] ^ (1U << (bit % 8)));
  if (fix_crc) bytes[11] = BitwiseCrc(bytes);
  return bytes;
}

void ExpectSameFrame(const Frame& a, const Frame& b) {
  EXPECT_EQ(a.opcode, b.opcode);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.pwm, b.pwm);
  EXPECT_EQ(a.enc, b.enc);
  EXPECT_EQ(a.raw, b.raw);
  EXPECT_EQ(a.init_request, b.init_request);
  EXPECT_EQ(a.init_answer, b.init_answer);
}

ChannelWords WordsOf(const Frame& f, Payload payload) {
  ChannelWords words = 0;
  for (std::size_t c = 0; c < kChannels; ++c) {
    words |= PlaceChannelWord(c, payload == Payload::kPwm ? PackPwm(f.pwm[c]) : PackEnc(f.enc[c]));
  }
  return words;
}

TEST(FrameFastPath, TheFrameCrcIsTheBitwiseCrcOnRandomFrames) {
  std::mt19937_64 rng(36);
  for (int i = 0; i < 100'000; ++i) {
    FrameBytes bytes;
    for (auto& b : bytes) b = Pick<std::uint8_t>(rng, 0, 255);
    if (i % 2 == 0) std::fill(bytes.begin() + 2, bytes.begin() + 10, 0);  // the empty-body CRC
    bytes[11] = BitwiseCrc(bytes);
    EXPECT_EQ(Crc8(bytes.data(), 11), bytes[11]);
    Frame decoded;
    const FrameError error = Decode(bytes, Direction::kAnswer, Image::kIcoboard, decoded);
    ASSERT_NE(error, FrameError::kChecksum) << i;  // the right CRC is accepted
    bytes[11] = static_cast<std::uint8_t>(bytes[11] ^ (1U << (i % 8)));
    ASSERT_EQ(Decode(bytes, Direction::kAnswer, Image::kIcoboard, decoded), FrameError::kChecksum);
  }
}

TEST(FrameFastPath, EncodeMatchesTheReferenceForEveryOpcodeDirectionAndImage) {
  std::mt19937_64 rng(3601);
  int encoded = 0;
  for (int i = 0; i < 20'000; ++i) {
    for (unsigned op = 0; op <= 13; ++op) {  // 13: not an opcode
      for (const Image image : kImages) {
        for (const Direction direction : kDirections) {
          const Frame f = RandomFrame(rng, op, i % 2 == 0);
          FrameBytes fast{};
          FrameBytes reference{};
          const FrameError error = Encode(f, direction, image, fast);
          ASSERT_EQ(error, RefEncode(f, direction, image, reference)) << op;
          if (error != FrameError::kOk) continue;
          ASSERT_EQ(fast, reference) << "op " << op;
          ++encoded;
        }
      }
    }
  }
  EXPECT_GT(encoded, 200'000);
}

TEST(FrameFastPath, DecodeMatchesTheReferenceOnValidDamagedAndRandomFrames) {
  std::mt19937_64 rng(3602);
  int accepted = 0;
  for (int i = 0; i < 30'000; ++i) {
    for (unsigned op = 0; op <= 12; ++op) {
      for (const Image image : kImages) {
        for (const Direction direction : kDirections) {
          FrameBytes bytes{};
          ASSERT_EQ(RefEncode(RandomFrame(rng, op, true), direction, image, bytes),
                    FrameError::kOk);
          if (i % 3 == 1) bytes = Damaged(rng, bytes, true);
          if (i % 3 == 2) {
            for (auto& b : bytes) b = Pick<std::uint8_t>(rng, 0, 255);
            if (i % 2 == 0) bytes[11] = BitwiseCrc(bytes);
          }
          // Both start from the same random frame: what a refusal or a per-channel frame leaves
          // untouched must be untouched in both.
          Frame fast = RandomFrame(rng, 12, false);
          Frame reference = fast;
          const FrameError error = Decode(bytes, direction, image, fast);
          ASSERT_EQ(error, RefDecode(bytes, direction, image, reference)) << op << " " << i;
          ExpectSameFrame(fast, reference);
          accepted += error == FrameError::kOk ? 1 : 0;
        }
      }
    }
  }
  EXPECT_GT(accepted, 400'000);
}

TEST(FrameFastPath, AllFramesWithoutAFrameMatchEncodeAndDecode) {
  std::mt19937_64 rng(3603);
  for (int i = 0; i < 50'000; ++i) {
    for (const Image image : kImages) {
      for (const Direction direction : kDirections) {
        const Payload payload = PayloadOf(Opcode::kAll, direction, image);
        const Frame f = RandomFrame(rng, 3, i % 4 != 0);  // a quarter with fields out of range
        const AllFrame all{f.sequence, f.status, WordsOf(f, payload)};
        FrameBytes general{};
        FrameBytes fast{};
        const FrameError error = Encode(f, direction, image, general);
        const bool representable = error != FrameError::kOutOfRange || payload == Payload::kPwm;
        if (representable) {
          ASSERT_EQ(EncodeAll(all, direction, image, fast), error) << i;
        }
        if (error == FrameError::kOk) {
          ASSERT_EQ(fast, general) << i;
        }

        // Decoding: valid, damaged (CRC repaired or not) and random bytes, ALL or not.
        FrameBytes bytes = general;
        if (error != FrameError::kOk || i % 3 == 1) {
          (void)RefEncode(RandomFrame(rng, 3, true), direction, image, bytes);
          bytes = Damaged(rng, bytes, i % 2 == 0);
        } else if (i % 3 == 2) {
          for (auto& b : bytes) b = Pick<std::uint8_t>(rng, 0, 255);
          if (i % 2 == 0) bytes[0] = 3;
          bytes[11] = BitwiseCrc(bytes);
        }
        Frame decoded = RandomFrame(rng, 3, false);
        const FrameError general_error = Decode(bytes, direction, image, decoded);
        const AllFrame before{1, 2, 0x1234};
        AllFrame got = before;
        const FrameError fast_error = DecodeAll(bytes, direction, image, got);
        // A frame that passes the CRC, opcode and status checks but is not ALL is Decode's to
        // judge: kOpcode.
        const bool header_ok = BitwiseCrc(bytes) == bytes[11] && bytes[0] <= 12 &&
                               (direction == Direction::kRequest ? bytes[10] == 0
                                                                 : (bytes[10] & 0xF0U) == 0);
        const bool other_opcode = header_ok && bytes[0] != 3;
        ASSERT_EQ(fast_error, other_opcode ? FrameError::kOpcode : general_error) << i;
        if (fast_error != FrameError::kOk) {
          ASSERT_EQ(got, before);
          continue;
        }
        ASSERT_EQ(got, (AllFrame{decoded.sequence, decoded.status, WordsOf(decoded, payload)}));
      }
    }
  }
}

TEST(FrameFastPath, EncodeAllRefusesTheWordsDecodeRefuses) {
  // A PWM magnitude above 2048 and an encoder word with its reserved bit 15.
  AllFrame pwm{1, 0, PlaceChannelWord(2, 2049)};
  FrameBytes bytes{};
  EXPECT_EQ(EncodeAll(pwm, Direction::kRequest, Image::kIcoboard, bytes), FrameError::kOutOfRange);
  pwm.words = PlaceChannelWord(2, 0xC000 | 2048);
  EXPECT_EQ(EncodeAll(pwm, Direction::kRequest, Image::kIcoboard, bytes), FrameError::kOk);
  const AllFrame enc{1, 0, PlaceChannelWord(3, 0x8000)};
  EXPECT_EQ(EncodeAll(enc, Direction::kRequest, Image::kIcoboardInverse, bytes),
            FrameError::kReservedBits);
  const AllFrame status{1, 0x10, 0};
  EXPECT_EQ(EncodeAll(status, Direction::kAnswer, Image::kIcoboardInverse, bytes),
            FrameError::kReservedBits);
  // A request carries no status: byte 10 is 0 whatever the frame says.
  EXPECT_EQ(EncodeAll(status, Direction::kRequest, Image::kIcoboardInverse, bytes),
            FrameError::kOk);
  EXPECT_EQ(bytes[10], 0);
}

}  // namespace
}  // namespace hiltwin::io
