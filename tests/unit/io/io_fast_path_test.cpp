// The per-cycle fast paths of the mock exchange against what they replace: the PWM reader's
// rounding without libm, ValueToCounts' floor without libm, the inline 14-bit wrap, the NOOP
// frames from the CRC tables, the encoder emulator's no-change period, the twin board's
// memoised PWM words and the untimed transfers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/io/icoboard.h"

namespace hiltwin::io {
namespace {

// ---- The references: the functions as they were (libm calls, the general paths). ----
std::int32_t RefPwmReaderValue(double duty) {
  if (std::isnan(duty)) return 0;
  double magnitude = std::fabs(duty);
  if (magnitude > 1.0) magnitude = 1.0;
  const auto high_clocks = static_cast<std::int32_t>(std::nearbyint(magnitude * 4096));
  std::int32_t value = high_clocks / 2;
  if (value > 2047) value = 2047;
  return duty < 0.0 ? -value : value;
}
std::int64_t RefValueToCounts(double value, double counts_per_unit) {
  const double counts = value * counts_per_unit;
  if (!std::isfinite(counts)) return 0;
  if (counts >= kMaxAbsCounts) return static_cast<std::int64_t>(kMaxAbsCounts);
  if (counts <= -kMaxAbsCounts) return -static_cast<std::int64_t>(kMaxAbsCounts);
  return static_cast<std::int64_t>(std::floor(counts));
}

TEST(IoFastPath, PwmReaderValueRoundsAsNearbyintOnTiesGridAndRandomDuties) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> duties = {0.0, -0.0, 1.0, -1.0, 1.5, -1.5, kInf, -kInf,
                                std::numeric_limits<double>::quiet_NaN(),
                                std::numeric_limits<double>::denorm_min(), 1e-300};
  // Every whole and half clock of the period (the ties round to even), and their neighbours.
  for (int half_clocks = 0; half_clocks <= 2 * 4096; ++half_clocks) {
    const double duty = half_clocks / 8192.0;
    for (const double d : {duty, std::nextafter(duty, 0.0), std::nextafter(duty, 2.0)}) {
      duties.push_back(d);
      duties.push_back(-d);
    }
  }
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> any(-1.2, 1.2);
  for (int i = 0; i < 200'000; ++i) duties.push_back(any(rng));
  for (const double duty : duties) {
    ASSERT_EQ(PwmReaderValue(duty), RefPwmReaderValue(duty)) << duty;
  }
}

TEST(IoFastPath, ValueToCountsFloorsAsStdFloor) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> values = {0.0, -0.0, 0.5, -0.5, 1.0, -1.0, -1e-300, 1e-300, kInf, -kInf,
                                std::numeric_limits<double>::quiet_NaN(), kMaxAbsCounts,
                                -kMaxAbsCounts, std::nextafter(kMaxAbsCounts, 0.0),
                                std::nextafter(-kMaxAbsCounts, 0.0), 4503599627370495.5,
                                -4503599627370495.5, 9007199254740993.0, -9007199254740993.0};
  std::mt19937_64 rng(3636);
  std::uniform_real_distribution<double> small(-1e4, 1e4);
  std::uniform_int_distribution<int> exponent(-30, 70);
  for (int i = 0; i < 200'000; ++i) {
    values.push_back(small(rng));
    values.push_back(std::ldexp(small(rng), exponent(rng)));
    values.push_back(std::round(small(rng)));  // whole values: floor is the value
  }
  for (const double v : values) {
    for (const double per_unit : {1.0, 1000.0, 13037.0}) {
      ASSERT_EQ(ValueToCounts(v, per_unit), RefValueToCounts(v, per_unit)) << v << " " << per_unit;
    }
  }
}

TEST(IoFastPath, InlineWrapIsTheGeneralWrapAt16384) {
  std::mt19937_64 rng(7);
  std::vector<std::int64_t> values = {0, 8191, 8192, -8192, -8193, 16384, -16384,
                                      std::numeric_limits<std::int64_t>::max(),
                                      std::numeric_limits<std::int64_t>::min()};
  for (int i = 0; i < 100'000; ++i) {
    values.push_back(static_cast<std::int64_t>(rng()));
    values.push_back(static_cast<std::int64_t>(rng() % 100'000) - 50'000);
  }
  for (const std::int64_t v : values) ASSERT_EQ(WrapToRelative(v), WrapToRelative(v, 16384)) << v;
}

TEST(IoFastPath, NoopFramesAreWhatEncodeAndDecodeMakeOfThem) {
  for (unsigned sequence = 0; sequence < 256; ++sequence) {
    for (unsigned status = 0; status <= kStatusMask; ++status) {
      Frame noop;
      noop.sequence = static_cast<std::uint8_t>(sequence);
      noop.status = static_cast<std::uint8_t>(status);
      FrameBytes expected;
      ASSERT_EQ(Encode(noop, Direction::kAnswer, Image::kIcoboard, expected), FrameError::kOk);
      FrameBytes got;
      got.fill(0xA5);
      EncodeNoop(noop.sequence, noop.status, got);
      ASSERT_EQ(got, expected) << sequence << " " << status;
    }
  }
  // IsNoopRequest accepts exactly what Decode accepts as a NOOP request: valid NOOPs, every
  // one-bit damage of them (CRC repaired and not), random frames.
  std::mt19937_64 rng(12);
  const auto decode_says = [](const FrameBytes& b) {
    Frame f;
    return Decode(b, Direction::kRequest, Image::kIcoboardInverse, f) == FrameError::kOk &&
           f.opcode == Opcode::kNoop;
  };
  int accepted = 0;
  for (unsigned sequence = 0; sequence < 256; ++sequence) {
    FrameBytes valid;
    EncodeNoop(static_cast<std::uint8_t>(sequence), 0, valid);
    ASSERT_TRUE(IsNoopRequest(valid));
    for (std::size_t bit = 0; bit < kFrameBytes * 8; ++bit) {
      FrameBytes damaged = valid;
      damaged[bit / 8] = static_cast<std::uint8_t>(damaged[bit / 8] ^ (1U << (bit % 8)));
      ASSERT_EQ(IsNoopRequest(damaged), decode_says(damaged)) << sequence << " " << bit;
      damaged[11] = Crc8(damaged.data(), 11);
      ASSERT_EQ(IsNoopRequest(damaged), decode_says(damaged)) << sequence << " " << bit;
      accepted += IsNoopRequest(damaged) ? 1 : 0;
    }
  }
  EXPECT_GT(accepted, 0);  // the repaired flips of the sequence byte are valid NOOPs
  for (int i = 0; i < 100'000; ++i) {
    FrameBytes b;
    for (auto& byte : b) byte = static_cast<std::uint8_t>(rng() % 3 == 0 ? rng() : 0);
    if (i % 2 == 0) b[11] = Crc8(b.data(), 11);
    ASSERT_EQ(IsNoopRequest(b), decode_says(b));
  }
}

/// StartPeriod as it was: the position reached by PositionAt, then Table 4.1 and the limit.
struct RefEmulator {
  PulseSegment segment;
  DifferenceCase last_case = DifferenceCase::kNone;
  std::uint64_t limit_events = 0;
  bool StartPeriod(std::int32_t target, std::int64_t t_ns, bool stuck) {
    const std::int32_t reached = segment.PositionAt(t_ns);
    segment.start_counts = reached;
    segment.start_ns = t_ns;
    if (stuck) {
      segment.pulses = 0;
      segment.direction = 0;
      return true;
    }
    const PulsePlan plan = PlanPulses(reached, WrapToRelative(target));
    last_case = plan.difference_case;
    segment.direction = plan.direction;
    const std::uint32_t most = MaxPulsesPerPeriod(segment.subticks);
    if (plan.pulses > most) {
      segment.pulses = most;
      ++limit_events;
      return false;
    }
    segment.pulses = plan.pulses;
    return true;
  }
};

TEST(IoFastPath, EncoderEmulatorNoChangePeriodsMatchTheGeneralPlan) {
  for (const std::int64_t step_ns : {250'000LL, 1'000'000LL, 20'000LL}) {
    const std::uint32_t divider = ClockDividerForStep(step_ns);
    EncoderEmulator emulator;
    ASSERT_TRUE(emulator.Configure(step_ns, divider));
    RefEmulator ref;
    ref.segment = emulator.segment();
    std::mt19937_64 rng(static_cast<std::uint64_t>(step_ns));
    std::int64_t t_ns = 0;
    std::int64_t target = 0;
    for (int i = 0; i < 50'000; ++i) {
      // Mostly whole periods and held targets (the fast path), sometimes early or late
      // sampling, small and large moves, a stuck line.
      const unsigned r = static_cast<unsigned>(rng() % 100);
      const auto span = static_cast<std::uint64_t>(2 * step_ns);
      const auto jitter = static_cast<std::int64_t>(rng() % span);
      t_ns += r < 80 ? step_ns : jitter - step_ns / 4;
      if (r % 7 == 0) target += static_cast<std::int64_t>(rng() % 201) - 100;
      if (r == 3) target += static_cast<std::int64_t>(rng() % 40'000) - 20'000;
      const bool stuck = r == 5 || r == 6;
      emulator.SetStuck(stuck);
      const auto relative = static_cast<std::int32_t>(target);
      ASSERT_EQ(emulator.StartPeriod(relative, t_ns), ref.StartPeriod(relative, t_ns, stuck)) << i;
      const PulseSegment& s = emulator.segment();
      ASSERT_EQ(s.start_counts, ref.segment.start_counts) << i;
      ASSERT_EQ(s.pulses, ref.segment.pulses) << i;
      ASSERT_EQ(s.direction, ref.segment.direction) << i;
      ASSERT_EQ(s.start_ns, ref.segment.start_ns) << i;
      ASSERT_EQ(emulator.last_case(), ref.last_case) << i;
      ASSERT_EQ(emulator.limit_events(), ref.limit_events) << i;
      const std::int64_t later_ns = t_ns + step_ns / 3;
      ASSERT_EQ(emulator.PositionAt(later_ns), ref.segment.PositionAt(later_ns)) << i;
    }
  }
}

/// A duty that holds for several frames, then moves.
class SteppedSource final : public PwmSignalSource {
 public:
  void DutyAt(std::int64_t /*t_ns*/, std::array<double, kChannels>& duty_out) noexcept override {
    for (std::size_t c = 0; c < kChannels; ++c) duty_out[c] = duty[c];
  }
  std::array<double, kChannels> duty{};
};

TEST(IoFastPath, TwinBoardsMemoisedPwmFollowsDutiesAndInputPins) {
  EmulatedFpga board{Image::kIcoboardInverse};
  EmulatedSpiBus bus{board};
  IcoBoardInverse driver{bus, UntimedTransfers()};
  SteppedSource source;
  board.SetPwmSource(&source);
  ASSERT_TRUE(driver.Init(250'000).ok);
  std::mt19937_64 rng(99);
  std::array<std::int32_t, kChannels> counts{};
  std::array<bool, kChannels> pins{};
  for (int i = 0; i < 2'000; ++i) {
    // Duties and pins change now and then, each on its own (the pins with duties held too).
    if (i % 5 == 0) {
      source.duty[rng() % kChannels] = (static_cast<double>(rng() % 2001) - 1000) / 1000;
    }
    if (i % 7 == 3) {
      pins[rng() % kChannels] = (rng() & 1U) != 0;
      board.SetDigitalInputs(pins);
    }
    TwinInputs in;
    ASSERT_TRUE(driver.Exchange(counts, in).ok()) << i;
    for (std::size_t c = 0; c < kChannels; ++c) {
      ASSERT_EQ(in.pwm[c], PwmReaderValue(source.duty[c])) << i << " " << c;
      ASSERT_EQ(board.pwm_measured()[c], in.pwm[c]);
      ASSERT_EQ(in.pins[c], pins[c]) << i << " " << c;
    }
  }
  // A re-INIT resets the measured values; the next frame measures the held duties again.
  ASSERT_TRUE(driver.Init(250'000).ok);
  TwinInputs in;
  ASSERT_TRUE(driver.Exchange(counts, in).ok());
  for (std::size_t c = 0; c < kChannels; ++c) EXPECT_EQ(in.pwm[c], PwmReaderValue(source.duty[c]));
  // Untimed transfers: counted, no duration.
  EXPECT_EQ(driver.timing().transfers, 2'000U + 2U + 1U);
  EXPECT_EQ(driver.timing().total_ns, 0);
  EXPECT_EQ(driver.timing().max_ns, 0);
}

}  // namespace
}  // namespace hiltwin::io
