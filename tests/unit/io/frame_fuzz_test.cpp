// Seeded random-frame fuzz of the decoder (the alternative to libFuzzer): 10^6 frames,
// run in the normal and the ASan+UBSan build. Every frame is judged by an independent reference
// validator written from docs/spi-protocol.md (bitwise CRC, its own payload table); the decoder
// must agree on every frame, accepted frames must re-encode to the same bytes, and rejected ones
// must leave the output untouched.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "hiltwin/io/frame.h"

namespace hiltwin::io {
namespace {

std::uint8_t ReferenceCrc(const FrameBytes& b) {
  unsigned crc = 0xFF;
  for (std::size_t i = 0; i < 11; ++i) {
    crc ^= b[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 0x80U) != 0 ? ((crc << 1U) ^ 0x2FU) & 0xFFU : (crc << 1U) & 0xFFU;
  }
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

bool ReferenceValid(const FrameBytes& b, bool request, bool ecs_host) {
  if (ReferenceCrc(b) != b[11]) return false;
  const unsigned op = b[0];
  if (op > 12) return false;
  if (request ? b[10] != 0 : (b[10] & 0xF0U) != 0) return false;
  auto word = [&](unsigned c) { return static_cast<unsigned>(b[2 + 2 * c] << 8U | b[3 + 2 * c]); };
  if (op == 0 || op == 2) {
    for (int i = 2; i < 10; ++i) {
      if (b[static_cast<std::size_t>(i)] != 0) return false;
    }
    return true;
  }
  if (op == 1) return request || b[5] == 0;
  if (op == 12) return true;
  bool pwm = false;
  if (op == 3) {
    pwm = request == ecs_host;  // ECS requests and twin answers carry PWM
  } else {
    pwm = op < 8;
  }
  for (unsigned c = 0; c < 4; ++c) {
    const bool used = op == 3 || (op & 3U) == c;
    const unsigned w = word(c);
    if (!used) {
      if (w != 0) return false;
    } else if (pwm) {
      if ((w & 0x3FFFU) > 2048) return false;
    } else if ((w & 0x8000U) != 0) {
      return false;
    }
  }
  return true;
}

TEST(FrameFuzz, DecoderAgreesWithTheReferenceOnAMillionRandomFrames) {
  std::mt19937_64 rng(20240611);
  constexpr int kFrames = 1'000'000;
  int accepted = 0;
  int rejected = 0;
  for (int i = 0; i < kFrames; ++i) {
    FrameBytes b;
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    const unsigned mode = static_cast<unsigned>(rng() % 4);
    // Mode 0: fully random. 1: random body, valid CRC. 2: valid-looking (opcode 0..12, zero
    // status) with valid CRC. 3: mode 2 plus one flipped bit.
    if (mode >= 2) {
      b[0] = static_cast<std::uint8_t>(rng() % 13);
      b[10] = static_cast<std::uint8_t>((rng() % 4 == 0) ? rng() % 16 : 0);
      if (rng() % 2 == 0) {
        for (std::size_t c = 0; c < 4; ++c) b[2 + 2 * c] = static_cast<std::uint8_t>(b[2 + 2 * c] & 0x47U);
      }
    }
    if (mode >= 1) b[11] = ReferenceCrc(b);
    if (mode == 3) {
      const auto bit = static_cast<unsigned>(rng() % 96);
      b[bit / 8] = static_cast<std::uint8_t>(b[bit / 8] ^ (1U << (bit % 8)));
    }
    const bool request = (rng() & 1U) != 0;
    const bool ecs_host = (rng() & 1U) != 0;
    const Direction direction = request ? Direction::kRequest : Direction::kAnswer;
    const Image image = ecs_host ? Image::kIcoboard : Image::kIcoboardInverse;

    Frame out;
    out.sequence = 0xA5;
    out.status = 0x0F;
    const FrameError error = Decode(b, direction, image, out);
    const bool expected = ReferenceValid(b, request, ecs_host);
    ASSERT_EQ(error == FrameError::kOk, expected) << "frame " << i << " error " << ToString(error);
    if (error == FrameError::kOk) {
      ++accepted;
      FrameBytes again;
      ASSERT_EQ(Encode(out, direction, image, again), FrameError::kOk) << i;
      ASSERT_EQ(again, b) << "frame " << i << " does not re-encode to itself";
    } else {
      ++rejected;
      ASSERT_EQ(out.sequence, 0xA5) << i;
      ASSERT_EQ(out.status, 0x0F) << i;
    }
  }
  // Both outcomes are exercised in volume.
  EXPECT_GT(accepted, kFrames / 50);
  EXPECT_GT(rejected, kFrames / 2);
}

}  // namespace
}  // namespace hiltwin::io
