// The answer register changes only while CS is high (spec15 §1, §3): a fetch that comes before
// the answer is ready reads the previous answer whole, never a mix of two. The gap between the
// request's CS rising edge and the fetch's CS falling edge is swept in 10 ns steps (with the
// SCLK phase moving against the clock), and the first gap that reads the fresh answer must be
// below the 2 µs the host leaves (the RTL promises 150 clocks after the last SCLK edge).
#include <gtest/gtest.h>

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/io/frame.h"
#include "rtl_frames.h"

namespace hiltwin::fpga_sim::test {
namespace {

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

TEST(EarlyFetch, ReadsThePreviousAnswerWholeNeverATornOne) {
  RtlBench bench(true, false, false);
  io::FrameBytes miso{};
  std::uint8_t seq = 0;
  bench.Transfer(Slot::kTwin, Init(seq++, 100'000, 4, io::Image::kIcoboardInverse), miso);
  bench.RunUntil(bench.now_ps() + 2'000'000);
  io::FrameBytes previous = Answer(io::Opcode::kNoop, seq, {});
  bench.Transfer(Slot::kTwin, Noop(seq++), miso);  // fetches INIT's answer
  bench.RunUntil(bench.now_ps() + 2'000'000);
  std::int64_t first_fresh_ns = -1;
  std::int64_t last_stale_ns = -1;
  int torn = 0;
  for (std::int64_t gap_ns = 0; gap_ns <= 2'000; gap_ns += 10) {
    const std::array<std::uint8_t, 8> raw = {static_cast<std::uint8_t>(gap_ns), 0xA5, 0x5A,
                                             static_cast<std::uint8_t>(gap_ns >> 8), 0xFF, 0, 1, 2};
    const std::uint8_t test_seq = seq++;
    bench.Transfer(Slot::kTwin, TestFrame(test_seq, raw), miso);  // reads `previous`
    EXPECT_EQ(miso, previous) << "gap " << gap_ns;
    bench.RunUntil(bench.now_ps() + gap_ns * 1000 + 137 * gap_ns % 10'000);
    const io::FrameBytes fresh = Answer(io::Opcode::kTest, test_seq, raw);
    const std::uint8_t fetch_seq = seq++;
    bench.Transfer(Slot::kTwin, Noop(fetch_seq), miso);
    if (miso == fresh) {
      if (first_fresh_ns < 0) first_fresh_ns = gap_ns;
    } else if (miso == previous) {
      last_stale_ns = gap_ns;
    } else {
      ++torn;
      ADD_FAILURE() << "gap " << gap_ns << " ns: torn answer " << Hex(miso) << "\n fresh "
                    << Hex(fresh) << "\n stale " << Hex(previous);
    }
    // The fetch NOOP is acted on too; its answer is what the next request reads.
    bench.RunUntil(bench.now_ps() + 2'000'000);
    previous = Answer(io::Opcode::kNoop, fetch_seq, {});
  }
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(last_stale_ns >= 0, true) << "no gap was short enough to read the stale answer";
  EXPECT_GE(first_fresh_ns, 0);
  EXPECT_LT(first_fresh_ns, 1'500);
  EXPECT_LT(last_stale_ns, first_fresh_ns);
  std::printf("answer latency: stale up to a %lld ns gap, fresh from %lld ns\n",
              static_cast<long long>(last_stale_ns), static_cast<long long>(first_fresh_ns));
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
