// SPI frames: the codec (io/frame.h) and the emulated board (io/emulated_fpga.h) of either
// image. Neither API throws: any crash, sanitizer report or broken property is a finding.
//
// Input: byte 0 chooses the image (bit 0) and whether each frame's CRC is made right (bit 1, so
// the fuzzer reaches past the checksum into the payload rules); the rest is a stream of
// 12-byte frames (a short tail is padded with zeros).
//
// Properties checked besides "no crash": a frame Decode accepts is re-encoded by Encode to the
// very same bytes (Decode "accepts exactly what Encode can produce"), and a refused frame
// leaves the output untouched.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/frame.h"

namespace {

using namespace hiltwin::io;

void CheckRoundTrip(const FrameBytes& bytes, Direction direction, Image image) {
  Frame decoded{};
  decoded.sequence = 0xA5;  // a sentinel: a refused frame must leave it
  const FrameError error = Decode(bytes, direction, image, decoded);
  if (error != FrameError::kOk) {
    if (decoded.sequence != 0xA5) {
      std::fprintf(stderr, "FINDING: Decode changed its output on %s\n", ToString(error));
      std::abort();
    }
    return;
  }
  FrameBytes encoded{};
  const FrameError back = Encode(decoded, direction, image, encoded);
  if (back != FrameError::kOk || encoded != bytes) {
    std::fprintf(stderr, "FINDING: a frame Decode accepts does not encode back (%s)\n",
                 ToString(back));
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const Image image = (data[0] & 1U) != 0 ? Image::kIcoboardInverse : Image::kIcoboard;
  const bool fix_crc = (data[0] & 2U) != 0;
  ++data;
  --size;

  EmulatedFpga board(image);  // no clock: board time counts data frames
  for (std::size_t offset = 0; offset < size; offset += kFrameBytes) {
    FrameBytes mosi{};
    std::copy_n(data + offset, std::min(kFrameBytes, size - offset), mosi.begin());
    if (fix_crc) mosi[kFrameBytes - 1] = Crc8(mosi.data(), kFrameBytes - 1);
    for (const Image host : {Image::kIcoboard, Image::kIcoboardInverse}) {
      CheckRoundTrip(mosi, Direction::kRequest, host);
      CheckRoundTrip(mosi, Direction::kAnswer, host);
    }
    FrameBytes miso{};
    board.Exchange(mosi, miso);
    // What the board sends must be a frame the host can decode, or the idle all-zero register.
    Frame answer{};
    if (miso != FrameBytes{} &&
        Decode(miso, Direction::kAnswer, image, answer) != FrameError::kOk) {
      std::fprintf(stderr, "FINDING: the board answered a frame that does not decode\n");
      std::abort();
    }
  }
  return 0;
}
