// The pipelined framing of docs/spi-protocol.md ("Pipelined answers"): the board's answer
// register (transfer n answers request n-1, zeros at power-up), the driver's NOOP fetch, fault
// injection that skips the fetches, an early fetch (stale, never torn), RESET mid-stream, the
// request/fetch pair timed as one transfer, and the INIT range of the twin image.
#include <gtest/gtest.h>

#include <vector>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::io {
namespace {

constexpr std::int64_t kPipelineStepNs = 250'000;  // 4 kHz
constexpr FrameBytes kZeros{};

FrameBytes Request(const Frame& frame, Image image = Image::kIcoboardInverse) {
  FrameBytes bytes{};
  EXPECT_EQ(Encode(frame, Direction::kRequest, image, bytes), FrameError::kOk);
  return bytes;
}

Frame TestFrame(std::uint8_t sequence, std::uint8_t first_byte) {
  Frame f;
  f.opcode = Opcode::kTest;
  f.sequence = sequence;
  f.raw = {first_byte, 2, 3, 4, 5, 6, 7, 8};
  return f;
}

Frame Noop(std::uint8_t sequence) {
  Frame f;
  f.sequence = sequence;
  return f;
}

Frame Init(std::uint8_t sequence, std::uint32_t step_ns, std::uint32_t divider) {
  Frame f;
  f.opcode = Opcode::kInit;
  f.sequence = sequence;
  f.init_request = {step_ns, divider};
  return f;
}

Frame Decoded(const FrameBytes& bytes, Image image = Image::kIcoboardInverse) {
  Frame f;
  EXPECT_EQ(Decode(bytes, Direction::kAnswer, image, f), FrameError::kOk);
  return f;
}

/// Sends `request` and fetches its answer with a NOOP, as the driver does.
Frame RequestAndFetch(EmulatedFpga& board, const Frame& request, std::uint8_t fetch_sequence) {
  FrameBytes miso{};
  board.Exchange(Request(request, board.image()), miso);
  board.Exchange(Request(Noop(fetch_sequence), board.image()), miso);
  return Decoded(miso, board.image());
}

TEST(AnswerRegister, TransferNCarriesTheAnswerToRequestNMinusOne) {
  EmulatedFpga board(Image::kIcoboardInverse);
  FrameBytes miso{};
  miso.fill(0x5A);
  board.Exchange(Request(TestFrame(10, 0)), miso);
  EXPECT_EQ(miso, kZeros);  // power-up: the register is all zeros (an idle MISO to the host)
  for (std::uint8_t n = 1; n < 20; ++n) {
    board.Exchange(Request(TestFrame(static_cast<std::uint8_t>(10 + n), n)), miso);
    const Frame answer = Decoded(miso);
    EXPECT_EQ(answer.opcode, Opcode::kTest);
    EXPECT_EQ(answer.sequence, 10 + n - 1) << "transfer " << int{n};
    EXPECT_EQ(answer.raw[0], n - 1);
  }
  // A NOOP is answered too (zero payload, its own sequence), and RESET's answer comes one late.
  board.Exchange(Request(Noop(99)), miso);
  board.Exchange(Request(Noop(100)), miso);
  EXPECT_EQ(Decoded(miso).opcode, Opcode::kNoop);
  EXPECT_EQ(Decoded(miso).sequence, 99);
  EXPECT_EQ(Decoded(miso).raw, (std::array<std::uint8_t, 8>{}));
}

TEST(AnswerRegister, TheAnswerSamplesWhenTheRequestIsActedUpon) {
  // The PWM an ALL answer carries is the reader's value at the ALL's transfer, not at the fetch.
  class StepSource final : public PwmSignalSource {
   public:
    void DutyAt(std::int64_t /*t_ns*/, std::array<double, kChannels>& duty_out) noexcept override {
      duty_out.fill(duty);
    }
    double duty = 0.25;
  } source;
  EmulatedFpga board(Image::kIcoboardInverse);
  board.SetPwmSource(&source);
  ASSERT_EQ(RequestAndFetch(board, Init(1, kPipelineStepNs, 4), 2).status & kStatusInitialised,
            kStatusInitialised);
  Frame all;
  all.opcode = Opcode::kAll;
  all.sequence = 3;
  FrameBytes miso{};
  board.Exchange(Request(all), miso);
  source.duty = -0.5;  // changes between the request and the fetch: not seen by this answer
  board.Exchange(Request(Noop(4)), miso);
  const Frame answer = Decoded(miso);
  EXPECT_EQ(answer.sequence, 3);
  EXPECT_EQ(answer.pwm[0].magnitude, 512);
  EXPECT_FALSE(answer.pwm[0].negative);
  EXPECT_EQ(board.data_frames(), 1U);  // the NOOP is not a data frame: board time unchanged
}

/// Records the MOSI of every transfer on its way to an emulated board.
class RecordingBus final : public SpiBus {
 public:
  explicit RecordingBus(SpiDevice& device) noexcept : device_(device) {}
  BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override {
    sent.push_back(mosi);
    device_.Exchange(mosi, miso);
    return {};
  }
  [[nodiscard]] const char* Name() const noexcept override { return "recording"; }
  std::vector<FrameBytes> sent;

 private:
  SpiDevice& device_;
};

TEST(Fetch, EveryExchangeIsTheRequestThenANoopWithTheNextSequenceNumber) {
  EmulatedFpga board(Image::kIcoboardInverse);
  RecordingBus bus(board);
  bus.sent.reserve(16);
  IcoBoardInverse driver(bus);
  ASSERT_TRUE(driver.Init(kPipelineStepNs).ok);
  TwinInputs in;
  ASSERT_TRUE(driver.Exchange({1, 2, 3, 4}, in).ok());
  ASSERT_EQ(bus.sent.size(), 4U);
  const Frame init = [&] {
    Frame f;
    EXPECT_EQ(Decode(bus.sent[0], Direction::kRequest, Image::kIcoboardInverse, f), FrameError::kOk);
    return f;
  }();
  EXPECT_EQ(init.opcode, Opcode::kInit);
  EXPECT_EQ(init.sequence, 1);
  EXPECT_EQ(bus.sent[1], Request(Noop(2)));
  EXPECT_EQ(bus.sent[2][0], static_cast<std::uint8_t>(Opcode::kAll));
  EXPECT_EQ(bus.sent[2][1], 3);
  EXPECT_EQ(bus.sent[3], Request(Noop(4)));
  // Counters and timing count exchanges, not transfers.
  EXPECT_EQ(driver.counters().init_frames_sent, 1U);
  EXPECT_EQ(driver.counters().frames_sent, 1U);
  EXPECT_EQ(driver.counters().frames_received, 1U);
  EXPECT_EQ(driver.timing().transfers, 2U);
  EXPECT_EQ(board.data_frames(), 1U);

  // The sequence numbers wrap after 128 exchanges; requests and answers stay paired.
  for (int k = 0; k < 300; ++k) ASSERT_TRUE(driver.Exchange({k, 0, 0, 0}, in).ok()) << k;
  EXPECT_EQ(driver.counters().frames_missed, 0U);
}

/// A bus whose fetch comes too early: it reaches the board before the board has acted on the
/// request (what a host that leaves no gap would see from the gateware), modelled by sending the
/// fetch first. The early fetch reads the previous answer: stale, never torn.
class EarlyFetchBus final : public SpiBus {
 public:
  explicit EarlyFetchBus(SpiDevice& device) noexcept : device_(device) {}
  BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override {
    device_.Exchange(mosi, miso);
    return {};
  }
  BusStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                         const FrameBytes& fetch, FrameBytes& answer) noexcept override {
    if (!early) return SpiBus::TransferPair(request, request_miso, fetch, answer);
    device_.Exchange(fetch, answer);
    device_.Exchange(request, request_miso);
    return {};
  }
  [[nodiscard]] const char* Name() const noexcept override { return "early-fetch"; }
  bool early = true;

 private:
  SpiDevice& device_;
};

TEST(Fetch, AnEarlyFetchReadsTheStaleAnswerAndIsCountedMissed) {
  EmulatedFpga board(Image::kIcoboardInverse);
  EarlyFetchBus bus(board);
  IcoBoardInverse driver(bus);
  // First exchange after power-up: the early fetch reads the all-zero register (idle); the
  // retries read the answer to the exchange before (stale sequence). Never a corrupted frame.
  std::array<std::uint8_t, 8> echo{};
  const ExchangeStatus first = driver.Test({1, 2, 3, 4, 5, 6, 7, 8}, echo);
  EXPECT_EQ(first.code, ExchangeStatus::Code::kMissed);
  EXPECT_STREQ(first.reason, "no answer from the board (MISO idle)");
  const InitResult init = driver.Init(kPipelineStepNs);  // resets the counters
  EXPECT_FALSE(init.ok);
  EXPECT_NE(init.message.find("stale answer"), std::string::npos) << init.message;
  EXPECT_EQ(driver.counters().init_frames_sent, 3U);
  EXPECT_EQ(driver.counters().frames_missed, 3U);
  EXPECT_EQ(driver.counters().frames_corrupted, 0U);
  EXPECT_TRUE(board.initialised());  // the board did act on INIT: only the answer was early

  bus.early = false;
  ASSERT_TRUE(driver.Init(kPipelineStepNs).ok);
  TwinInputs in;
  ASSERT_TRUE(driver.Exchange({5, 0, 0, 0}, in).ok());
  bus.early = true;
  const ExchangeStatus s = driver.Exchange({6, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kMissed);
  EXPECT_STREQ(s.reason, "stale answer (sequence number of an earlier request)");
  EXPECT_EQ(board.encoder(0).PositionAt(1'000'000'000), 6);  // the request itself arrived
  bus.early = false;
  EXPECT_TRUE(driver.Exchange({7, 0, 0, 0}, in).ok());
}

TEST(Fetch, FirstTransferAfterPowerUpIsIdleToTheDriver) {
  // A host that never fetches reads the register of power-up on its first transfer.
  EmulatedFpga board(Image::kIcoboard);
  class NoFetchBus final : public SpiBus {
   public:
    explicit NoFetchBus(SpiDevice& device) noexcept : device_(device) {}
    BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override {
      device_.Exchange(mosi, miso);
      return {};
    }
    BusStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                           const FrameBytes& /*fetch*/, FrameBytes& answer) noexcept override {
      device_.Exchange(request, request_miso);
      answer = request_miso;
      return {};
    }
    [[nodiscard]] const char* Name() const noexcept override { return "no-fetch"; }

   private:
    SpiDevice& device_;
  } bus(board);
  IcoBoard driver(bus);
  std::array<std::uint8_t, 8> echo{};
  const ExchangeStatus first = driver.Test({1, 2, 3, 4, 5, 6, 7, 8}, echo);
  EXPECT_EQ(first.code, ExchangeStatus::Code::kMissed);
  EXPECT_STREQ(first.reason, "no answer from the board (MISO idle)");
  // Without the fetch every later answer belongs to the request before: stale.
  const ExchangeStatus second = driver.Test({1, 2, 3, 4, 5, 6, 7, 8}, echo);
  EXPECT_EQ(second.code, ExchangeStatus::Code::kMissed);
  EXPECT_STREQ(second.reason, "stale answer (sequence number of an earlier request)");
  EXPECT_EQ(driver.counters().frames_missed, 2U);
}

TEST(FaultInjection, RequestAndAnswerFaultsSkipNoops) {
  EmulatedFpga board(Image::kIcoboardInverse);
  FrameBytes miso{};
  // Request faults: a NOOP passes untouched and leaves the count for the next real request.
  board.faults().corrupt_requests = 1;
  board.Exchange(Request(Noop(1)), miso);
  EXPECT_EQ(board.requests_rejected(), 0U);
  EXPECT_EQ(board.faults().corrupt_requests, 1U);
  board.Exchange(Request(TestFrame(2, 0)), miso);
  EXPECT_EQ(board.requests_rejected(), 1U);
  EXPECT_EQ(board.faults().corrupt_requests, 0U);
  board.Exchange(Request(Noop(3)), miso);
  EXPECT_NE(Decoded(miso).status & kStatusRequestRejected, 0);

  // Answer faults: the answer to a NOOP leaves untouched, the answer to TEST is dropped.
  board.faults().drop_answers = 1;
  board.Exchange(Request(TestFrame(4, 4)), miso);  // shifts out the NOOP's answer
  EXPECT_EQ(Decoded(miso).sequence, 3);
  EXPECT_EQ(board.faults().drop_answers, 1U);
  board.Exchange(Request(Noop(5)), miso);  // shifts out TEST 4's answer: dropped
  FrameBytes idle;
  idle.fill(0xFF);
  EXPECT_EQ(miso, idle);
  EXPECT_EQ(board.faults().drop_answers, 0U);

  // Corrupt: one bit of the answer to TEST flips.
  board.faults().corrupt_answers = 1;
  board.Exchange(Request(TestFrame(6, 6)), miso);
  EXPECT_EQ(board.faults().corrupt_answers, 1U);
  board.Exchange(Request(Noop(7)), miso);
  Frame ignored;
  EXPECT_NE(Decode(miso, Direction::kAnswer, Image::kIcoboardInverse, ignored), FrameError::kOk);
  EXPECT_EQ(board.faults().corrupt_answers, 0U);

  // Delay: the answer to TEST is replaced by what the board sent in the transfer before.
  board.faults().delay_answers = 1;
  board.Exchange(Request(TestFrame(8, 8)), miso);  // shifts out NOOP 7's answer
  const FrameBytes before = miso;
  EXPECT_EQ(Decoded(before).sequence, 7);
  board.Exchange(Request(Noop(9)), miso);
  EXPECT_EQ(miso, before);
  EXPECT_EQ(board.faults().delay_answers, 0U);
  board.Exchange(Request(Noop(10)), miso);
  EXPECT_EQ(Decoded(miso).sequence, 9);  // back to normal
}

TEST(FaultInjection, TheNextNCountsExchangesThroughTheDriver) {
  EmulatedFpga board(Image::kIcoboardInverse);
  EmulatedSpiBus bus(board);
  IcoBoardInverse driver(bus);
  ASSERT_TRUE(driver.Init(kPipelineStepNs).ok);
  TwinInputs in;
  struct Case {
    std::uint32_t FaultInjection::*hook;
    ExchangeStatus::Code code;
  };
  for (const Case& c : {Case{&FaultInjection::corrupt_requests, ExchangeStatus::Code::kCorrupted},
                        Case{&FaultInjection::corrupt_answers, ExchangeStatus::Code::kCorrupted},
                        Case{&FaultInjection::drop_answers, ExchangeStatus::Code::kMissed},
                        Case{&FaultInjection::delay_answers, ExchangeStatus::Code::kMissed}}) {
    board.faults().*c.hook = 3;
    for (int k = 0; k < 3; ++k) EXPECT_EQ(driver.Exchange({k, 0, 0, 0}, in).code, c.code) << k;
    EXPECT_TRUE(driver.Exchange({9, 0, 0, 0}, in).ok());
  }
  EXPECT_EQ(driver.counters().frames_corrupted, 6U);
  EXPECT_EQ(driver.counters().frames_missed, 6U);
  EXPECT_EQ(driver.counters().frames_received, 4U);
}

TEST(AnswerRegister, ResetMidStream) {
  EmulatedFpga board(Image::kIcoboard);
  EmulatedSpiBus bus(board);
  IcoBoard driver(bus);
  ASSERT_TRUE(driver.Init(1'000'000).ok);
  EcsInputs in;
  ASSERT_TRUE(driver.Exchange({100, 0, 0, 0}, in).ok());
  // Another host resets the board between two exchanges: RESET's answer (INITIALISED clear) is
  // in the register, so the driver's next request transfer shifts it out, unread.
  Frame reset;
  reset.opcode = Opcode::kReset;
  reset.sequence = 200;
  FrameBytes miso{};
  board.Exchange(Request(reset, Image::kIcoboard), miso);
  EXPECT_EQ(Decoded(miso, Image::kIcoboard).opcode, Opcode::kNoop);  // the driver's last fetch
  EXPECT_FALSE(board.initialised());
  EXPECT_EQ(board.pwm_output()[0], 0);
  // The driver's ALL reaches an uninitialised board: its fetched answer lacks INITIALISED.
  const ExchangeStatus s = driver.Exchange({100, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kFault);
  EXPECT_EQ(board.pwm_output()[0], 0);  // and the board did not act on it
  ASSERT_TRUE(driver.Init(1'000'000).ok);
  EXPECT_TRUE(driver.Exchange({100, 0, 0, 0}, in).ok());

  // RESET through a request/fetch pair: the fetch carries RESET's answer, INITIALISED clear.
  const Frame answer = RequestAndFetch(board, reset, 201);
  EXPECT_EQ(answer.opcode, Opcode::kReset);
  EXPECT_EQ(answer.sequence, 200);
  EXPECT_EQ(answer.status & kStatusInitialised, 0);
}

/// A bus whose every transfer takes 1 µs of virtual time.
class SlowBus final : public SpiBus {
 public:
  explicit SlowBus(kernel_glue::VirtualClock& clock) noexcept : clock_(clock) {}
  BusStatus Transfer(const FrameBytes& /*mosi*/, FrameBytes& miso) noexcept override {
    clock_.AdvanceNs(1'000);
    ++calls;
    miso.fill(0);
    return fail ? BusStatus{BusResult::kIoError, "broken"} : BusStatus{};
  }
  [[nodiscard]] const char* Name() const noexcept override { return "slow"; }
  int calls = 0;
  bool fail = false;

 private:
  kernel_glue::VirtualClock& clock_;
};

TEST(TimedSpi, ThePairIsTimedAndCountedAsOneTransfer) {
  kernel_glue::VirtualClock clock(5'000);
  SlowBus bus(clock);
  TimedSpi spi(bus, &clock);
  FrameBytes a{};
  FrameBytes b{};
  const TransferStatus pair = spi.TransferPair(kZeros, a, kZeros, b);
  EXPECT_EQ(pair.result, BusResult::kOk);
  EXPECT_EQ(pair.start_ns, 5'000);
  EXPECT_EQ(pair.duration_ns, 2'000);
  EXPECT_EQ(bus.calls, 2);
  EXPECT_EQ(spi.timing().transfers, 1U);
  EXPECT_EQ(spi.timing().total_ns, 2'000);
  EXPECT_EQ(spi.timing().max_ns, 2'000);
  (void)spi.Transfer(kZeros, a);
  EXPECT_EQ(spi.timing().transfers, 2U);
  EXPECT_EQ(spi.timing().total_ns, 3'000);
  EXPECT_EQ(spi.timing().max_ns, 2'000);
  // The default pair stops after a failed request transfer.
  bus.fail = true;
  const TransferStatus failed = spi.TransferPair(kZeros, a, kZeros, b);
  EXPECT_EQ(failed.result, BusResult::kIoError);
  EXPECT_STREQ(failed.reason, "broken");
  EXPECT_EQ(bus.calls, 4);
  EXPECT_EQ(failed.duration_ns, 1'000);
}

TEST(InitRange, EncoderEmulatorAcceptsExactlyTheDocumentedRange) {
  EncoderEmulator e;
  // step_ns >= 10
  EXPECT_FALSE(e.Configure(9, 4));
  EXPECT_FALSE(e.Configure(0, 4));
  EXPECT_FALSE(e.Configure(-40, 4));
  // 4 <= D <= 65535
  EXPECT_FALSE(e.Configure(1'000'000, 3));
  EXPECT_TRUE(e.Configure(1'000'000, 4));
  EXPECT_TRUE(e.Configure(655'350, 65'535));    // S = 1
  EXPECT_FALSE(e.Configure(655'360, 65'536));   // S = 1 but D too large
  EXPECT_FALSE(e.Configure(4'294'967'295, 65'536));
  // 1 <= S <= 65535 with S = floor(floor(step_ns / 10) / D)
  EXPECT_FALSE(e.Configure(39, 4));             // 3 clocks: S = 0
  EXPECT_TRUE(e.Configure(40, 4));              // S = 1
  EXPECT_TRUE(e.Configure(49, 4));              // floor(49 / 10) = 4: S = 1
  EXPECT_FALSE(e.Configure(655'349, 65'535));   // S = 0
  EXPECT_TRUE(e.Configure(2'621'400, 4));       // S = 65535
  EXPECT_EQ(e.segment().subticks, 65'535U);
  EXPECT_TRUE(e.Configure(2'621'439, 4));       // 262143 clocks / 4: S = 65535
  EXPECT_FALSE(e.Configure(2'621'440, 4));      // S = 65536
  EXPECT_TRUE(e.Configure(2'621'440, 5));       // S = 52428
  // A rejected INIT leaves the previous parameters.
  EXPECT_EQ(e.segment().subticks, 52'428U);
  EXPECT_EQ(e.segment().divider, 5U);
}

TEST(InitRange, TheHostsDividerIsAlwaysInRange) {
  EncoderEmulator e;
  for (std::int64_t step_ns : {40LL, 100LL, 20'000LL, 250'000LL, 1'000'000LL, 81'920'000LL,
                               81'929'999LL, 1'000'000'000LL, 4'294'967'295LL}) {
    const std::uint32_t divider = ClockDividerForStep(step_ns);
    EXPECT_TRUE(e.Configure(step_ns, divider)) << step_ns;
    EXPECT_LE(divider, 52'428U);
    EXPECT_LE(SubticksPerStep(step_ns, divider), 16'383U) << step_ns;
  }
}

TEST(InitRange, TheBoardsAnswerTheRange) {
  struct Case {
    Image image;
    std::uint32_t step_ns;
    std::uint32_t divider;
    bool accepted;
  };
  const Case cases[] = {
      {Image::kIcoboardInverse, 9, 4, false},
      {Image::kIcoboardInverse, 10, 4, false},  // S = 0
      {Image::kIcoboardInverse, 40, 4, true},
      {Image::kIcoboardInverse, 250'000, 3, false},
      {Image::kIcoboardInverse, 655'350, 65'535, true},
      {Image::kIcoboardInverse, 655'360, 65'536, false},
      {Image::kIcoboardInverse, 2'621'439, 4, true},
      {Image::kIcoboardInverse, 2'621'440, 4, false},
      {Image::kIcoboard, 9, 0, false},
      {Image::kIcoboard, 10, 0, true},  // the ECS image has no emulator: step only
      {Image::kIcoboard, 10, 1'000'000, true},
      {Image::kIcoboard, 4'294'967'295U, 0, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << ToString(c.image) << " step " << c.step_ns << " D "
                                    << c.divider);
    EmulatedFpga board(c.image);
    const Frame answer = RequestAndFetch(board, Init(1, c.step_ns, c.divider), 2);
    EXPECT_EQ(answer.opcode, Opcode::kInit);
    EXPECT_EQ(answer.sequence, 1);
    EXPECT_EQ(board.initialised(), c.accepted);
    EXPECT_EQ((answer.status & kStatusInitialised) != 0, c.accepted);
    EXPECT_EQ((answer.status & kStatusInitRejected) != 0, !c.accepted);
    const std::uint32_t accepted_divider =
        c.accepted && c.image == Image::kIcoboardInverse ? c.divider : 0;
    EXPECT_EQ(answer.init_answer.clock_divider, accepted_divider);
    EXPECT_EQ(answer.init_answer.identity, IdentityOf(c.image));
  }
}

}  // namespace
}  // namespace hiltwin::io
