#include "hiltwin/io/frame.h"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace hiltwin::io {
namespace {

constexpr Image kImages[] = {Image::kIcoboard, Image::kIcoboardInverse};
constexpr Direction kDirections[] = {Direction::kRequest, Direction::kAnswer};

/// A frame with every field of its payload set to something non-trivial.
Frame Sample(Opcode opcode, std::uint8_t sequence, Direction direction) {
  Frame f;
  f.opcode = opcode;
  f.sequence = sequence;
  f.status = direction == Direction::kAnswer ? std::uint8_t{kStatusInitialised | kStatusPulseLimit}
                                             : std::uint8_t{0};
  f.pwm = {PwmWord{2048, true, true}, PwmWord{0, false, false}, PwmWord{1, true, false},
           PwmWord{1234, false, true}};
  f.enc = {EncWord{-8192, true}, EncWord{8191, false}, EncWord{-1, false}, EncWord{0, true}};
  f.raw = {0, 1, 0x7F, 0x80, 0xFE, 0xFF, 0x55, 0xAA};
  f.init_request = {0xFFFF'FFFFU, 12};
  f.init_answer = {kProtocolVersion, 4, kIdentityIcoboardInverse, 0xFFFF'FFFFU};
  return f;
}

void ExpectPayloadEqual(const Frame& a, const Frame& b, Direction direction, Image image) {
  EXPECT_EQ(a.opcode, b.opcode);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.status, b.status);
  const Payload payload = PayloadOf(a.opcode, direction, image);
  const auto v = static_cast<unsigned>(a.opcode);
  for (std::size_t c = 0; c < kChannels; ++c) {
    const bool used = !(v >= 4 && v <= 11) || (v & 3U) == c;
    if (!used) continue;
    if (payload == Payload::kPwm) {
      EXPECT_EQ(a.pwm[c], b.pwm[c]) << c;
    }
    if (payload == Payload::kEnc) {
      EXPECT_EQ(a.enc[c], b.enc[c]) << c;
    }
  }
  if (payload == Payload::kRaw) {
    EXPECT_EQ(a.raw, b.raw);
  }
  if (payload == Payload::kInitRequest) {
    EXPECT_EQ(a.init_request, b.init_request);
  }
  if (payload == Payload::kInitAnswer) {
    EXPECT_EQ(a.init_answer, b.init_answer);
  }
}

TEST(Crc8, MatchesTheAutosarCheckValue) {
  const char* text = "123456789";
  EXPECT_EQ(Crc8(reinterpret_cast<const std::uint8_t*>(text), 9), 0xDF);
}

TEST(Frame, RoundTripsEveryOpcodeDirectionAndImage) {
  for (unsigned op = 0; op <= 12; ++op) {
    for (const Image image : kImages) {
      for (const Direction direction : kDirections) {
        const Frame original = Sample(static_cast<Opcode>(op), static_cast<std::uint8_t>(op * 17), direction);
        FrameBytes bytes;
        ASSERT_EQ(Encode(original, direction, image, bytes), FrameError::kOk) << op;
        Frame decoded;
        ASSERT_EQ(Decode(bytes, direction, image, decoded), FrameError::kOk) << op;
        ExpectPayloadEqual(original, decoded, direction, image);
        FrameBytes again;
        ASSERT_EQ(Encode(decoded, direction, image, again), FrameError::kOk);
        EXPECT_EQ(bytes, again) << "op " << op;
      }
    }
  }
}

TEST(Frame, AllCarriesPwmFromTheEcsAndEncodersFromTheTwin) {
  EXPECT_EQ(PayloadOf(Opcode::kAll, Direction::kRequest, Image::kIcoboard), Payload::kPwm);
  EXPECT_EQ(PayloadOf(Opcode::kAll, Direction::kAnswer, Image::kIcoboard), Payload::kEnc);
  EXPECT_EQ(PayloadOf(Opcode::kAll, Direction::kRequest, Image::kIcoboardInverse), Payload::kEnc);
  EXPECT_EQ(PayloadOf(Opcode::kAll, Direction::kAnswer, Image::kIcoboardInverse), Payload::kPwm);
  EXPECT_EQ(PayloadOf(Opcode::kPwm3, Direction::kAnswer, Image::kIcoboard), Payload::kPwm);
  EXPECT_EQ(PayloadOf(Opcode::kEnc0, Direction::kRequest, Image::kIcoboardInverse), Payload::kEnc);
}

TEST(Frame, FieldsAtTheirLimits) {
  // PWM magnitude 0..2048 with both direction and pin bits; 2049 is out of range.
  for (const std::uint16_t magnitude : {std::uint16_t{0}, std::uint16_t{1}, std::uint16_t{2047},
                                        std::uint16_t{2048}}) {
    Frame f;
    f.opcode = Opcode::kAll;
    f.pwm.fill(PwmWord{magnitude, true, true});
    FrameBytes bytes;
    ASSERT_EQ(Encode(f, Direction::kRequest, Image::kIcoboard, bytes), FrameError::kOk);
    Frame d;
    ASSERT_EQ(Decode(bytes, Direction::kRequest, Image::kIcoboard, d), FrameError::kOk);
    EXPECT_EQ(d.pwm[3], (PwmWord{magnitude, true, true}));
  }
  Frame too_big;
  too_big.opcode = Opcode::kAll;
  too_big.pwm[1].magnitude = 2049;
  FrameBytes bytes;
  EXPECT_EQ(Encode(too_big, Direction::kRequest, Image::kIcoboard, bytes), FrameError::kOutOfRange);

  // Encoder field: -8192 and 8191 survive, sign-extended; one beyond does not encode.
  for (const std::int16_t counts : {std::int16_t{-8192}, std::int16_t{-1}, std::int16_t{0},
                                    std::int16_t{8191}}) {
    Frame f;
    f.opcode = Opcode::kAll;
    f.enc.fill(EncWord{counts, true});
    ASSERT_EQ(Encode(f, Direction::kRequest, Image::kIcoboardInverse, bytes), FrameError::kOk);
    Frame d;
    ASSERT_EQ(Decode(bytes, Direction::kRequest, Image::kIcoboardInverse, d), FrameError::kOk);
    EXPECT_EQ(d.enc[0].counts, counts);
    EXPECT_TRUE(d.enc[0].pin);
  }
  Frame beyond;
  beyond.opcode = Opcode::kAll;
  beyond.enc[2].counts = 8192;
  EXPECT_EQ(Encode(beyond, Direction::kRequest, Image::kIcoboardInverse, bytes),
            FrameError::kOutOfRange);
  beyond.enc[2].counts = -8193;
  EXPECT_EQ(Encode(beyond, Direction::kRequest, Image::kIcoboardInverse, bytes),
            FrameError::kOutOfRange);

  // INIT: the full u32 range in both fields; sequence 255 and every status bit.
  Frame init;
  init.opcode = Opcode::kInit;
  init.sequence = 255;
  init.init_request = {0xFFFF'FFFFU, 0xFFFF'FFFFU};
  ASSERT_EQ(Encode(init, Direction::kRequest, Image::kIcoboardInverse, bytes), FrameError::kOk);
  EXPECT_EQ(bytes[1], 255);
  Frame d;
  ASSERT_EQ(Decode(bytes, Direction::kRequest, Image::kIcoboardInverse, d), FrameError::kOk);
  EXPECT_EQ(d.init_request, init.init_request);
  init.status = kStatusMask;
  ASSERT_EQ(Encode(init, Direction::kAnswer, Image::kIcoboard, bytes), FrameError::kOk);
  ASSERT_EQ(Decode(bytes, Direction::kAnswer, Image::kIcoboard, d), FrameError::kOk);
  EXPECT_EQ(d.status, kStatusMask);
  init.status = 0x10;
  EXPECT_EQ(Encode(init, Direction::kAnswer, Image::kIcoboard, bytes), FrameError::kReservedBits);
}

/// Encodes, flips/changes something, fixes the CRC, and expects `error`.
void ExpectRejected(Frame f, Direction direction, Image image, std::size_t byte, std::uint8_t value,
                    FrameError error) {
  FrameBytes bytes;
  ASSERT_EQ(Encode(f, direction, image, bytes), FrameError::kOk);
  bytes[byte] = value;
  bytes[11] = Crc8(bytes.data(), 11);
  Frame out;
  out.sequence = 0x5A;  // sentinel: must survive a rejected decode
  EXPECT_EQ(Decode(bytes, direction, image, out), error) << "byte " << byte;
  EXPECT_EQ(out.sequence, 0x5A);
}

TEST(Frame, InvalidFramesAreRejectedAndLeaveTheOutputUntouched) {
  Frame all;
  all.opcode = Opcode::kAll;
  ExpectRejected(all, Direction::kRequest, Image::kIcoboard, 0, 13, FrameError::kOpcode);
  ExpectRejected(all, Direction::kRequest, Image::kIcoboard, 0, 0xFF, FrameError::kOpcode);
  ExpectRejected(all, Direction::kRequest, Image::kIcoboard, 10, 0x01, FrameError::kReservedBits);
  ExpectRejected(all, Direction::kAnswer, Image::kIcoboard, 10, 0x10, FrameError::kReservedBits);
  // PWM magnitude 2049 (0x0801) in slot 0 of an ECS request.
  FrameBytes bytes;
  ASSERT_EQ(Encode(all, Direction::kRequest, Image::kIcoboard, bytes), FrameError::kOk);
  bytes[2] = 0x08;
  bytes[3] = 0x01;
  bytes[11] = Crc8(bytes.data(), 11);
  Frame out;
  EXPECT_EQ(Decode(bytes, Direction::kRequest, Image::kIcoboard, out), FrameError::kOutOfRange);
  // Encoder bit 15 is reserved.
  ExpectRejected(all, Direction::kAnswer, Image::kIcoboard, 4, 0x80, FrameError::kReservedBits);
  // Unused slots of a per-channel frame, payload of NOOP/RESET, INIT answer byte 5.
  Frame pwm1;
  pwm1.opcode = Opcode::kPwm1;
  ExpectRejected(pwm1, Direction::kAnswer, Image::kIcoboardInverse, 2, 0x01, FrameError::kReservedBits);
  Frame noop;
  ExpectRejected(noop, Direction::kRequest, Image::kIcoboard, 9, 0x01, FrameError::kReservedBits);
  Frame init;
  init.opcode = Opcode::kInit;
  ExpectRejected(init, Direction::kAnswer, Image::kIcoboard, 5, 0x01, FrameError::kReservedBits);
}

TEST(Frame, CorruptedFramesAreRejected) {
  const Frame f = Sample(Opcode::kAll, 42, Direction::kAnswer);
  FrameBytes good;
  ASSERT_EQ(Encode(f, Direction::kAnswer, Image::kIcoboardInverse, good), FrameError::kOk);
  // Every 1-, 2- and 3-bit error of the frame is caught by the CRC (or the field checks).
  int accepted = 0;
  const int bits = static_cast<int>(kFrameBytes * 8);
  auto flip = [](FrameBytes& b, int bit) {
    b[static_cast<std::size_t>(bit / 8)] =
        static_cast<std::uint8_t>(b[static_cast<std::size_t>(bit / 8)] ^ (1U << (bit % 8)));
  };
  for (int i = 0; i < bits; ++i) {
    for (int j = i; j < bits; ++j) {
      for (int k = j; k < bits; ++k) {
        FrameBytes bad = good;
        flip(bad, i);
        if (j != i) flip(bad, j);
        if (k != j) flip(bad, k);
        if (bad == good) continue;
        Frame out;
        if (Decode(bad, Direction::kAnswer, Image::kIcoboardInverse, out) == FrameError::kOk) {
          ++accepted;
        }
      }
    }
  }
  EXPECT_EQ(accepted, 0);

  // A silent bus: all zeros and all ones are not frames.
  FrameBytes zeros{};
  FrameBytes ones;
  ones.fill(0xFF);
  Frame out;
  EXPECT_NE(Decode(zeros, Direction::kAnswer, Image::kIcoboard, out), FrameError::kOk);
  EXPECT_NE(Decode(ones, Direction::kAnswer, Image::kIcoboard, out), FrameError::kOk);
}

TEST(Frame, ImagesAndIdentities) {
  EXPECT_EQ(IdentityOf(Image::kIcoboard), 11);
  EXPECT_NE(IdentityOf(Image::kIcoboardInverse), 11);
  EXPECT_EQ(ImageOfIdentity(11), Image::kIcoboard);
  EXPECT_EQ(ImageOfIdentity(kIdentityIcoboardInverse), Image::kIcoboardInverse);
  EXPECT_FALSE(ImageOfIdentity(0).has_value());
  EXPECT_EQ(ParseImage("icoboard"), Image::kIcoboard);
  EXPECT_EQ(ParseImage("icoboard_inverse"), Image::kIcoboardInverse);
  EXPECT_FALSE(ParseImage("inverse").has_value());
  EXPECT_STREQ(ToString(Image::kIcoboardInverse), "icoboard_inverse");
  EXPECT_EQ(Counterpart(Image::kIcoboard), Image::kIcoboardInverse);
  EXPECT_EQ(PwmOpcode(2), Opcode::kPwm2);
  EXPECT_EQ(EncOpcode(3), Opcode::kEnc3);
}

}  // namespace
}  // namespace hiltwin::io
