// The answer register changes only while CS is high (spec15 §1, §3): a fetch that comes before
// the answer is ready reads the previous answer whole, never a mix of two. The gap between the
// request's CS rising edge and the fetch's CS falling edge is swept in 10 ns steps (with the
// SCLK phase moving against the clock), and the first gap that reads the fresh answer must be
// below the 2 µs the host leaves (the RTL promises 150 clocks after the last SCLK edge). The
// answer time depends on the request: NOOP and TEST are answered first, ALL after its board
// step, the twin's INIT last (its range check divides twice); docs/fpga.md quotes these figures.
#include <gtest/gtest.h>

#include <functional>

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/io/frame.h"
#include "rtl_frames.h"

namespace hiltwin::fpga_sim::test {
namespace {

constexpr std::uint32_t kEarlyFetchStepNs = 100'000;

io::FrameBytes Answer(io::Opcode opcode, std::uint8_t sequence, const std::array<std::uint8_t, 8>& raw) {
  io::Frame f;
  f.opcode = opcode;
  f.sequence = sequence;
  f.raw = raw;
  f.status = io::kStatusInitialised;
  io::FrameBytes bytes{};
  EXPECT_EQ(io::Encode(f, io::Direction::kAnswer, io::Image::kIcoboardInverse, bytes), io::FrameError::kOk);
  return bytes;
}

/// One kind of request whose answer time is measured.
struct RequestKind {
  const char* name;
  io::Image image;  ///< the board's image (the host driver's)
  /// The request with sequence `seq`; `gap_ns` varies its payload where it has one.
  std::function<io::FrameBytes(std::uint8_t seq, std::int64_t gap_ns)> request;
};

/// Where the fetch stops reading the previous answer and starts reading the fresh one.
struct Sweep {
  std::int64_t last_stale_ns = -1;
  std::int64_t first_fresh_ns = -1;
  int torn = 0;
};

/// Fresh: the answer to exactly this request (its opcode and sequence, not rejected, valid CRC).
bool IsAnswerTo(const io::FrameBytes& miso, const io::FrameBytes& request, io::Image image) {
  io::Frame answer;
  return io::Decode(miso, io::Direction::kAnswer, image, answer) == io::FrameError::kOk &&
         miso[0] == request[0] && miso[1] == request[1] &&
         (answer.status & io::kStatusRequestRejected) == 0;
}

Sweep SweepFetchGap(const RequestKind& kind) {
  const Slot slot = kind.image == io::Image::kIcoboardInverse ? Slot::kTwin : Slot::kEcs;
  RtlBench bench(slot == Slot::kTwin, slot == Slot::kEcs, false);
  io::FrameBytes miso{};
  std::uint8_t seq = 0;
  bench.Transfer(slot, Init(seq++, kEarlyFetchStepNs, 4, kind.image), miso);
  bench.RunUntil(bench.now_ps() + 2'000'000);
  io::FrameBytes previous = Answer(io::Opcode::kNoop, seq, {});
  bench.Transfer(slot, Noop(seq++), miso);  // fetches INIT's answer
  bench.RunUntil(bench.now_ps() + 2'000'000);
  Sweep sweep;
  for (std::int64_t gap_ns = 0; gap_ns <= 2'000; gap_ns += 10) {
    const io::FrameBytes request = kind.request(seq++, gap_ns);
    bench.Transfer(slot, request, miso);  // reads `previous`
    EXPECT_EQ(miso, previous) << kind.name << ", gap " << gap_ns;
    bench.RunUntil(bench.now_ps() + gap_ns * 1000 + 137 * gap_ns % 10'000);
    const std::uint8_t fetch_seq = seq++;
    bench.Transfer(slot, Noop(fetch_seq), miso);
    if (IsAnswerTo(miso, request, kind.image)) {
      if (sweep.first_fresh_ns < 0) sweep.first_fresh_ns = gap_ns;
    } else if (miso == previous) {
      sweep.last_stale_ns = gap_ns;
    } else {
      ++sweep.torn;
      ADD_FAILURE() << kind.name << ", gap " << gap_ns << " ns: torn answer " << Hex(miso)
                    << "\n stale " << Hex(previous);
    }
    // The fetch NOOP is acted on too; its answer is what the next request reads.
    bench.RunUntil(bench.now_ps() + 2'000'000);
    previous = Answer(io::Opcode::kNoop, fetch_seq, {});
  }
  return sweep;
}

TEST(EarlyFetch, ReadsThePreviousAnswerWholeNeverATornOne) {
  const RequestKind kinds[] = {
      {"NOOP", io::Image::kIcoboardInverse, [](std::uint8_t s, std::int64_t) { return Noop(s); }},
      {"TEST", io::Image::kIcoboardInverse,
       [](std::uint8_t s, std::int64_t gap) {
         return TestFrame(s, {static_cast<std::uint8_t>(gap), 0xA5, 0x5A,
                              static_cast<std::uint8_t>(gap >> 8), 0xFF, 0, 1, 2});
       }},
      {"ALL (twin)", io::Image::kIcoboardInverse,
       [](std::uint8_t s, std::int64_t gap) {
         const auto counts = static_cast<std::int32_t>(gap % 200);
         return AllTwin(s, {counts, -counts, 0, 0});
       }},
      {"ALL (ECS)", io::Image::kIcoboard,
       [](std::uint8_t s, std::int64_t gap) {
         const auto pwm = static_cast<std::int32_t>(gap % 2048);
         return AllEcs(s, {pwm, -pwm, 0, 0});
       }},
      {"INIT (twin)", io::Image::kIcoboardInverse,
       [](std::uint8_t s, std::int64_t) {
         return Init(s, kEarlyFetchStepNs, 4, io::Image::kIcoboardInverse);
       }},
      {"INIT (ECS)", io::Image::kIcoboard,
       [](std::uint8_t s, std::int64_t) {
         return Init(s, kEarlyFetchStepNs, 0, io::Image::kIcoboard);
       }},
  };
  for (const RequestKind& kind : kinds) {
    const Sweep sweep = SweepFetchGap(kind);
    EXPECT_EQ(sweep.torn, 0) << kind.name;
    EXPECT_GE(sweep.last_stale_ns, 0)
        << kind.name << ": no gap was short enough to read the stale answer";
    EXPECT_GE(sweep.first_fresh_ns, 0) << kind.name;
    EXPECT_LT(sweep.first_fresh_ns, 1'500) << kind.name;
    EXPECT_LT(sweep.last_stale_ns, sweep.first_fresh_ns) << kind.name;
    std::printf("answer latency, %-11s: stale up to a %lld ns gap, fresh from %lld ns\n",
                kind.name, static_cast<long long>(sweep.last_stale_ns),
                static_cast<long long>(sweep.first_fresh_ns));
  }
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
