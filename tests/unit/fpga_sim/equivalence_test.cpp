// Bit-identical answers, RTL vs the C++ board model (io::EmulatedFpga, pipelined as in spec15
// §1): the same MOSI sequence goes to both, transfer by transfer, and every MISO byte must
// match. The sequences mix random bytes, every opcode, corrupted CRCs, reserved bits, RESET in
// the middle of the stream, INIT with out-of-range steps and dividers (spec15 §2), and ALLs with
// random encoder targets (wraps, reversals, changes over the pulse limit) or PWM values; the twin
// board reads constant PWM duties on its inputs. The same runner sweeps the SCLK phase against
// the 100 MHz clock and the SCLK rate (the clock-domain crossing at 31.25 MHz).
#include <gtest/gtest.h>

#include <random>

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/fpga_sim/verilated_board.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_emulator.h"
#include "rtl_frames.h"

namespace hiltwin::fpga_sim::test {
namespace {

constexpr std::uint32_t kEquivalenceStepNs = 250'000;  // room for long runs of non-ALL transfers

class ConstantDuty final : public io::PwmSignalSource {
 public:
  void DutyAt(std::int64_t /*t_ns*/, std::array<double, io::kChannels>& duty_out) noexcept override {
    duty_out = {0.3, -0.55, 0.9999, 0.0};
  }
};

/// Builds the request stream.
class Script {
 public:
  Script(io::Image image, std::uint64_t seed) : image_(image), rng_(seed) {}

  void Request(const io::FrameBytes& bytes, bool fetch_after) {
    frames_.push_back(bytes);
    if (fetch_after) frames_.push_back(Noop(Seq()));
  }
  std::uint8_t Seq() { return sequence_++; }
  void ValidInit() { Request(Init(Seq(), kEquivalenceStepNs, io::ClockDividerForStep(kEquivalenceStepNs), image_), true); }

  std::vector<io::FrameBytes> Make(int actions) {
    ValidInit();
    for (int i = 0; i < actions; ++i) Action();
    return frames_;
  }

 private:
  std::uint32_t Roll(std::uint32_t n) { return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng_); }
  bool Fetch() { return Roll(10) < 8; }

  io::FrameBytes RandomBytes() {
    io::FrameBytes b{};
    for (auto& byte : b) byte = static_cast<std::uint8_t>(Roll(256));
    b[0] = static_cast<std::uint8_t>(Roll(4) == 0 ? Roll(256) : Roll(16));
    return b;
  }

  io::FrameBytes All() {
    std::array<std::int32_t, 4> v{};
    for (std::size_t c = 0; c < 4; ++c) {
      if (image_ == io::Image::kIcoboardInverse) {
        const std::uint32_t kind = Roll(10);
        target_[c] += kind < 6 ? static_cast<std::int32_t>(Roll(201)) - 100
                      : kind < 9 ? static_cast<std::int32_t>(Roll(5001)) - 2500
                                 : static_cast<std::int32_t>(Roll(16384));
        target_[c] = io::WrapToRelative(target_[c]);
        v[c] = target_[c];
      } else {
        v[c] = static_cast<std::int32_t>(Roll(4096)) - 2048;
      }
    }
    const auto pins = static_cast<std::uint8_t>(Roll(16));
    return image_ == io::Image::kIcoboardInverse ? AllTwin(Seq(), v, pins) : AllEcs(Seq(), v, pins);
  }

  void OutOfRangeInit() {
    static constexpr std::array<std::uint32_t, 9> kSteps = {0, 5, 9, 10, 11, 40, 12'345, 655'350, 4'000'000'000};
    static constexpr std::array<std::uint32_t, 9> kDividers = {0, 1, 3, 4, 5, 65'535, 65'536, 0xFFFFFF, 0xFFFFFFFF};
    Request(Init(Seq(), kSteps[Roll(9)], kDividers[Roll(9)], image_), true);
    ValidInit();  // never run ALLs on a step the device would have to wait seconds for
  }

  void Action() {
    const std::uint32_t roll = Roll(100);
    if (roll < 40) {
      Request(All(), Fetch());
    } else if (roll < 50) {
      Request(Simple(static_cast<io::Opcode>(4 + Roll(8)), Seq(), image_), Fetch());
    } else if (roll < 58) {
      std::array<std::uint8_t, 8> raw{};
      for (auto& b : raw) b = static_cast<std::uint8_t>(Roll(256));
      Request(TestFrame(Seq(), raw), Fetch());
    } else if (roll < 66) {
      Request(RandomBytes(), Fetch());  // almost always a bad CRC
    } else if (roll < 76) {
      Request(WithCrc(RandomBytes()), Fetch());  // good CRC: opcode, reserved bits, ranges decide
    } else if (roll < 82) {
      io::FrameBytes b = All();
      b[Roll(12)] ^= static_cast<std::uint8_t>(1U << Roll(8));  // one bit flipped: CRC fails
      Request(b, Fetch());
    } else if (roll < 86) {
      Request(Noop(Seq()), false);
    } else if (roll < 89) {
      Request(Simple(io::Opcode::kReset, Seq(), image_), Fetch());
      for (int i = 0; i < 3; ++i) Request(All(), true);  // ignored: not initialised
      ValidInit();
      target_.fill(0);
    } else if (roll < 93) {
      OutOfRangeInit();
      target_.fill(0);
    } else if (roll < 96) {
      Request(WithCrc({static_cast<std::uint8_t>(13 + Roll(3)), Seq(), 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}), Fetch());
    } else {
      Request(Simple(io::Opcode::kAll, Seq(), image_), Fetch());  // ALL with a zero payload
    }
  }

  io::Image image_;
  std::mt19937_64 rng_;
  std::uint8_t sequence_ = 0;
  std::vector<io::FrameBytes> frames_;
  std::array<std::int32_t, 4> target_{};
};

struct Mismatches {
  std::size_t transfers = 0;
  std::size_t differing = 0;
  std::string first;
};

Mismatches RunBoth(io::Image image, const std::vector<io::FrameBytes>& frames,
                   const DeviceTiming& timing) {
  const bool twin = image == io::Image::kIcoboardInverse;
  RtlBench bench(twin, !twin, false);
  VerilatedBoardDevice rtl(bench, image, timing);
  io::EmulatedFpga model(image);
  ConstantDuty duty;
  model.SetPwmSource(&duty);
  rtl.SetPwmSource(&duty);
  const std::array<bool, 4> pins = {true, false, true, true};
  model.SetDigitalInputs(pins);
  rtl.SetDigitalInputs(pins);
  if (twin) {
    // The reader measures whole 4096-clock periods: put the waveform on before the first ALL.
    std::array<double, 4> d{};
    duty.DutyAt(0, d);
    for (std::size_t c = 0; c < 4; ++c) {
      bench.SetPwmInput(c, static_cast<std::uint32_t>(std::nearbyint(std::fabs(d[c]) * 4096)), d[c] < 0);
    }
    bench.RunClocks(3 * 4096);
  }
  std::vector<io::FrameBytes> from_model(frames.size());
  std::vector<io::FrameBytes> from_rtl(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    model.Exchange(frames[i], from_model[i]);
    rtl.Exchange(frames[i], from_rtl[i]);
  }
  Mismatches out;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ++out.transfers;
    if (from_model[i] != from_rtl[i] && ++out.differing <= 8) {
      out.first += "transfer " + std::to_string(i) + ": MOSI " + Hex(frames[i]) + "\n  model " +
                   Hex(from_model[i]) + "\n  RTL   " + Hex(from_rtl[i]) + "\n";
    }
  }
  EXPECT_LE(rtl.max_late_ns(), 0) << "an ALL started later than its board time";
  return out;
}

struct Case {
  io::Image image;
  std::uint64_t seed;
};

class RtlMatchesTheModel : public ::testing::TestWithParam<Case> {};

TEST_P(RtlMatchesTheModel, EveryMisoByteOfARandomStream) {
  const Case& param = GetParam();
  const std::vector<io::FrameBytes> frames = Script(param.image, param.seed).Make(3000);
  const Mismatches m = RunBoth(param.image, frames, DeviceTiming{});
  EXPECT_EQ(m.differing, 0U) << m.first;
  std::printf("%zu transfers, %zu differ\n", m.transfers, m.differing);
}

INSTANTIATE_TEST_SUITE_P(BothImages, RtlMatchesTheModel,
                         ::testing::Values(Case{io::Image::kIcoboardInverse, 1},
                                           Case{io::Image::kIcoboardInverse, 2},
                                           Case{io::Image::kIcoboard, 3},
                                           Case{io::Image::kIcoboard, 4}),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                           return std::string(param_info.param.image == io::Image::kIcoboard ? "Ecs" : "Twin") +
                                  "Seed" + std::to_string(param_info.param.seed);
                         });

struct Clocking {
  std::int64_t sclk_hz;
  std::int64_t lead_ps;
};

class SclkPhase : public ::testing::TestWithParam<Clocking> {};

TEST_P(SclkPhase, FramesCrossIntoTheClockDomainIntact) {
  DeviceTiming timing;
  timing.shape.sclk_hz = GetParam().sclk_hz;
  timing.shape.lead_ps = GetParam().lead_ps;
  for (const io::Image image : {io::Image::kIcoboardInverse, io::Image::kIcoboard}) {
    const std::vector<io::FrameBytes> frames = Script(image, 77).Make(300);
    const Mismatches m = RunBoth(image, frames, timing);
    EXPECT_EQ(m.differing, 0U) << m.first;
  }
}

// SCLK edges at every 1.25 ns of the 10 ns clock period (31.25 MHz: the half period of 16 ns is
// not a multiple of 10 ns, so within one frame the edges also walk across the clock), and at
// 25 MHz (half period 20 ns: every edge at the same clock phase) and 10 MHz.
INSTANTIATE_TEST_SUITE_P(
    Offsets, SclkPhase,
    ::testing::Values(Clocking{31'250'000, 0}, Clocking{31'250'000, 1'250}, Clocking{31'250'000, 2'500},
                      Clocking{31'250'000, 3'750}, Clocking{31'250'000, 5'000},
                      Clocking{31'250'000, 6'250}, Clocking{31'250'000, 7'500},
                      Clocking{31'250'000, 8'750}, Clocking{25'000'000, 0}, Clocking{25'000'000, 5'000},
                      Clocking{25'000'000, 9'999}, Clocking{10'000'000, 3'000}),
    [](const ::testing::TestParamInfo<Clocking>& param_info) {
      return "Sclk" + std::to_string(param_info.param.sclk_hz / 1000) + "kHzLead" +
             std::to_string(param_info.param.lead_ps) + "ps";
    });

}  // namespace
}  // namespace hiltwin::fpga_sim::test
