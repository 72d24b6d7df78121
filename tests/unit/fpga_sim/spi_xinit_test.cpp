// The SPI front end (board/fpga/rtl/spi_slave.v) is defined from the first SCLK edge whatever
// its flip-flops power up with. The model is verilated with --x-initial unique and each run
// starts every register at another random value (the stand-in for X in a two-state simulator):
// with CS high from power-up there is no CS edge before the first transfer, so only the
// registers' initial values can put the bit counters at 0. A counter that starts elsewhere
// shifts MISO and frames the request at the wrong bit.
#include <gtest/gtest.h>
#include <verilated.h>

#include <array>
#include <cstdint>
#include <memory>

#include "Vspi_slave_xinit.h"
#include "hiltwin/io/frame.h"
#include "rtl_frames.h"

namespace hiltwin::fpga_sim::test {
namespace {

constexpr int kBits = static_cast<int>(io::kFrameBytes * 8);

/// Bit `i` (0 = byte 0's MSB, the first on the wire) of a frame.
bool BitOf(const io::FrameBytes& frame, int i) {
  return ((frame[static_cast<std::size_t>(i / 8)] >> (7 - i % 8)) & 1U) != 0;
}

/// The frame as the 96-bit register the RTL holds: byte 0 in bits 95..88.
void ToWords(const io::FrameBytes& frame, VlWide<3>& words) {
  for (int w = 0; w < 3; ++w) words[w] = 0;
  for (int i = 0; i < kBits; ++i) {
    if (BitOf(frame, i)) words[(95 - i) / 32] |= 1U << ((95 - i) % 32);
  }
}

io::FrameBytes FromWords(const VlWide<3>& words) {
  io::FrameBytes frame{};
  for (int i = 0; i < kBits; ++i) {
    if (((words[(95 - i) / 32] >> ((95 - i) % 32)) & 1U) != 0) {
      frame[static_cast<std::size_t>(i / 8)] |= static_cast<std::uint8_t>(0x80U >> (i % 8));
    }
  }
  return frame;
}

/// spi_slave alone, every register random at power-up (seeded), CS high from the start.
class RandomisedSpiSlave {
 public:
  explicit RandomisedSpiSlave(std::uint64_t seed) {
    context_.randReset(2);  // --x-initial unique: random
    context_.randSeed(static_cast<int>(seed));
    top_ = std::make_unique<Vspi_slave_xinit>(&context_, "spi");
    top_->clk = 0;
    top_->rst = 1;
    top_->spi_sclk = 0;
    top_->spi_mosi = 0;
    top_->spi_cs_n = 1;
    top_->take = 0;
    top_->eval();
  }

  Vspi_slave_xinit& top() { return *top_; }

  void Clock() {
    top_->clk = 1;
    top_->eval();
    top_->clk = 0;
    top_->eval();
  }

  /// Mode 0, MSB first: MOSI set and MISO sampled before each rising edge, the next bit after
  /// each falling edge; CS rises after the last falling edge.
  io::FrameBytes Transfer(const io::FrameBytes& mosi) {
    io::FrameBytes miso{};
    top_->spi_cs_n = 0;
    top_->eval();
    for (int i = 0; i < kBits; ++i) {
      top_->spi_mosi = BitOf(mosi, i) ? 1 : 0;
      top_->eval();
      if (top_->spi_miso != 0) {
        miso[static_cast<std::size_t>(i / 8)] |= static_cast<std::uint8_t>(0x80U >> (i % 8));
      }
      top_->spi_sclk = 1;
      top_->eval();
      top_->spi_sclk = 0;
      top_->eval();
    }
    top_->spi_cs_n = 1;
    top_->eval();
    return miso;
  }

 private:
  VerilatedContext context_;
  std::unique_ptr<Vspi_slave_xinit> top_;
};

TEST(SpiSlaveFromPowerUp, MisoAndTheRequestAreDefinedFromTheFirstEdgeWhateverTheRegistersHeld) {
  const io::FrameBytes answer = WithCrc({0xA5, 0x3C, 0x0F, 0xF0, 0x81, 0x7E, 1, 2, 3, 4, 0x55});
  const io::FrameBytes request = Init(1, 250'000, 4, io::Image::kIcoboardInverse);
  int wrong = 0;
  for (std::uint64_t seed = 1; seed <= 16; ++seed) {
    RandomisedSpiSlave spi(seed);
    ToWords(answer, spi.top().answer);
    for (int k = 0; k < 20; ++k) spi.Clock();  // the power-on reset, then idle
    spi.top().rst = 0;
    for (int k = 0; k < 4; ++k) spi.Clock();
    ASSERT_EQ(spi.top().pending, 0) << "seed " << seed << ": a request before any transfer";
    const io::FrameBytes miso = spi.Transfer(request);
    for (int k = 0; k < 4; ++k) spi.Clock();  // the toggle crosses into clk
    const bool pending = spi.top().pending != 0;
    spi.top().take = 1;
    spi.Clock();
    spi.top().take = 0;
    const io::FrameBytes received = FromWords(spi.top().request);
    if (miso != answer || !pending || received != request) {
      ++wrong;
      ADD_FAILURE() << "seed " << seed << ": first transfer after power-up\n MISO     "
                    << Hex(miso) << "\n expected " << Hex(answer) << "\n request "
                    << (pending ? "taken " + Hex(received) : std::string("never complete"))
                    << "\n sent     " << Hex(request);
    }
  }
  EXPECT_EQ(wrong, 0) << "of 16 random power-up states";
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
