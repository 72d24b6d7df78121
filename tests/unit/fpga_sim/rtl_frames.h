#pragma once
// Request frames for the co-simulation tests, and a printable form of frame bytes.

#include <cstdio>
#include <random>
#include <string>

#include "hiltwin/io/frame.h"

namespace hiltwin::fpga_sim::test {

inline io::FrameBytes WithCrc(io::FrameBytes bytes) {
  bytes[11] = io::Crc8(bytes.data(), 11);
  return bytes;
}

inline std::string Hex(const io::FrameBytes& bytes) {
  std::string out;
  char buf[4];
  for (const std::uint8_t b : bytes) {
    std::snprintf(buf, sizeof buf, "%02X ", b);
    out += buf;
  }
  return out;
}

inline io::FrameBytes Encoded(const io::Frame& frame, io::Image image) {
  io::FrameBytes bytes{};
  if (io::Encode(frame, io::Direction::kRequest, image, bytes) != io::FrameError::kOk) {
    throw std::invalid_argument("test frame does not encode");
  }
  return bytes;
}

inline io::FrameBytes Noop(std::uint8_t sequence) {
  io::Frame f;
  f.sequence = sequence;
  return Encoded(f, io::Image::kIcoboard);
}

inline io::FrameBytes Init(std::uint8_t sequence, std::uint32_t step_ns, std::uint32_t divider,
                           io::Image image) {
  io::Frame f;
  f.opcode = io::Opcode::kInit;
  f.sequence = sequence;
  f.init_request = {step_ns, divider};
  return Encoded(f, image);
}

inline io::FrameBytes Simple(io::Opcode opcode, std::uint8_t sequence, io::Image image) {
  io::Frame f;
  f.opcode = opcode;
  f.sequence = sequence;
  return Encoded(f, image);
}

inline io::FrameBytes TestFrame(std::uint8_t sequence, const std::array<std::uint8_t, 8>& raw) {
  io::Frame f;
  f.opcode = io::Opcode::kTest;
  f.sequence = sequence;
  f.raw = raw;
  return Encoded(f, io::Image::kIcoboard);
}

/// ALL to the twin: encoder targets (relative, 14-bit) and pins.
inline io::FrameBytes AllTwin(std::uint8_t sequence, const std::array<std::int32_t, 4>& counts,
                              std::uint8_t pins = 0) {
  io::Frame f;
  f.opcode = io::Opcode::kAll;
  f.sequence = sequence;
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    f.enc[c] = io::EncWord{static_cast<std::int16_t>(counts[c]), ((unsigned{pins} >> c) & 1U) != 0};
  }
  return Encoded(f, io::Image::kIcoboardInverse);
}

/// ALL to the ECS: PWM values [-2048, 2047] and pins.
inline io::FrameBytes AllEcs(std::uint8_t sequence, const std::array<std::int32_t, 4>& pwm,
                             std::uint8_t pins = 0) {
  io::Frame f;
  f.opcode = io::Opcode::kAll;
  f.sequence = sequence;
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    const std::int32_t v = pwm[c];
    f.pwm[c] = io::PwmWord{static_cast<std::uint16_t>(v < 0 ? -v : v), v < 0, ((unsigned{pins} >> c) & 1U) != 0};
  }
  return Encoded(f, io::Image::kIcoboard);
}

}  // namespace hiltwin::fpga_sim::test
