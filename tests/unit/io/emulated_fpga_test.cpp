// The drivers against the emulated FPGA (mock backend): INIT and the identity check, values in
// both directions, the deterministic board time, every fault-injection hook, the pulse-limit
// report, an ECS board wired to a twin board in one process, and no allocation per cycle.
#include "hiltwin/io/emulated_fpga.h"

#include <gtest/gtest.h>

#include <vector>

#include "fakes/alloc_counter.h"
#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::io {
namespace {

constexpr std::int64_t kFpgaStepNs = 250'000;  // 4 kHz

/// Duty that depends on time, so the test can tell which instant the board sampled.
class RampSource final : public PwmSignalSource {
 public:
  void DutyAt(std::int64_t t_ns, std::array<double, kChannels>& duty_out) noexcept override {
    times.push_back(t_ns);
    for (std::size_t c = 0; c < kChannels; ++c) duty_out[c] = Duty(t_ns, c);
  }
  static double Duty(std::int64_t t_ns, std::size_t c) {
    const double x = static_cast<double>(t_ns % 10'000'000) / 10'000'000.0;  // 0..1 over 10 ms
    return (c % 2 == 0 ? 1.0 : -1.0) * x * (0.25 + 0.25 * static_cast<double>(c));
  }
  std::vector<std::int64_t> times;
};

struct TwinRig {
  EmulatedFpga board{Image::kIcoboardInverse};
  EmulatedSpiBus bus{board};
  kernel_glue::VirtualClock clock;
  IcoBoardInverse driver{bus, &clock};
};

TEST(IcoBoardInverse, InitChecksIdentityAndSendsStepAndDivider) {
  TwinRig rig;
  const InitResult init = rig.driver.Init(kFpgaStepNs);
  ASSERT_TRUE(init.ok) << init.message;
  EXPECT_TRUE(init.image_known);
  EXPECT_EQ(init.found, Image::kIcoboardInverse);
  EXPECT_EQ(init.identity, kIdentityIcoboardInverse);
  EXPECT_EQ(init.clock_divider, ClockDividerForStep(kFpgaStepNs));
  EXPECT_TRUE(rig.board.initialised());
  EXPECT_EQ(rig.board.step_ns(), kFpgaStepNs);
  EXPECT_EQ(rig.board.clock_divider(), ClockDividerForStep(kFpgaStepNs));
  // INIT is counted apart: frames_sent and frames_received are data frames only.
  EXPECT_EQ(rig.driver.counters().init_frames_sent, 1U);
  EXPECT_EQ(rig.driver.counters().init_frames_received, 1U);
  EXPECT_EQ(rig.driver.counters().frames_sent, 0U);
  EXPECT_EQ(rig.driver.counters().frames_received, 0U);
  EXPECT_THROW((void)rig.driver.Init(5), std::invalid_argument);
}

TEST(IcoBoardInverse, WrongImageFailsWithTheThesisStyleMessage) {
  EmulatedFpga ecs_board(Image::kIcoboard);
  EmulatedSpiBus bus(ecs_board);
  IcoBoardInverse twin(bus);
  const InitResult init = twin.Init(kFpgaStepNs);
  EXPECT_FALSE(init.ok);
  EXPECT_EQ(init.found, Image::kIcoboard);
  EXPECT_EQ(init.message.rfind("Failed to initialise FPGA: found icoboard, the twin needs "
                               "icoboard_inverse", 0), 0U)
      << init.message;
  EXPECT_FALSE(twin.initialised());

  EmulatedFpga twin_board(Image::kIcoboardInverse);
  EmulatedSpiBus bus2(twin_board);
  IcoBoard ecs(bus2);
  const InitResult init2 = ecs.Init(1'000'000);
  EXPECT_FALSE(init2.ok);
  EXPECT_EQ(init2.message.rfind("Failed to initialise FPGA: found icoboard_inverse, the ECS "
                                "needs icoboard", 0), 0U)
      << init2.message;

  // The fault hook: a board that answers as the other image.
  TwinRig rig;
  rig.board.faults().answer_as_image = Image::kIcoboard;
  EXPECT_FALSE(rig.driver.Init(kFpgaStepNs).ok);
}

TEST(IcoBoardInverse, ExchangeCarriesValuesAndBoardTimeIsFramesTimesStep) {
  TwinRig rig;
  RampSource source;
  rig.board.SetPwmSource(&source);
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  TwinInputs in;
  for (int k = 0; k < 50; ++k) {
    const std::array<std::int32_t, kChannels> out = {k * 10, -k * 10, k * 1000, 20000 + k};
    const ExchangeStatus status = rig.driver.Exchange(out, in);
    ASSERT_TRUE(status.ok()) << status.reason;
    const std::int64_t t_ns = k * kFpgaStepNs;
    ASSERT_EQ(source.times.back(), t_ns);
    for (std::size_t c = 0; c < kChannels; ++c) {
      const std::int32_t expected = PwmReaderValue(RampSource::Duty(t_ns, c));
      EXPECT_EQ(in.pwm[c], expected) << k << " " << c;
      EXPECT_DOUBLE_EQ(in.duty[c], expected / 2048.0);
      // At the end of this period the emulator has emitted the (wrapped) position sent.
      EXPECT_EQ(rig.board.encoder(c).PositionAt(t_ns + kFpgaStepNs), WrapToRelative(out[c]));
    }
  }
  EXPECT_EQ(rig.board.data_frames(), 50U);
  EXPECT_EQ(rig.driver.counters().frames_sent, 50U);
  EXPECT_EQ(rig.driver.counters().frames_received, 50U);
  EXPECT_EQ(rig.driver.counters().init_frames_received, 1U);
  EXPECT_EQ(rig.driver.counters().frames_corrupted + rig.driver.counters().frames_missed, 0U);
}

TEST(IcoBoardInverse, DigitalPinsTravelBothWays) {
  TwinRig rig;
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  rig.board.SetDigitalInputs({true, false, false, true});
  rig.driver.SetDigitalOutputs({false, true, true, false});
  TwinInputs in;
  ASSERT_TRUE(rig.driver.Exchange({0, 0, 0, 0}, in).ok());
  EXPECT_EQ(in.pins, (std::array<bool, kChannels>{true, false, false, true}));
  EXPECT_EQ(rig.board.pins_out(), (std::array<bool, kChannels>{false, true, true, false}));
}

TEST(IcoBoardInverse, FaultInjectionIsDetectedAndValuesAreHeld) {
  TwinRig rig;
  RampSource source;
  rig.board.SetPwmSource(&source);
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  TwinInputs in;
  ASSERT_TRUE(rig.driver.Exchange({100, 0, 0, 0}, in).ok());
  ASSERT_TRUE(rig.driver.Exchange({100, 0, 0, 0}, in).ok());  // non-zero ramp from k = 1 on
  const TwinInputs held = in;
  ASSERT_NE(held.pwm[0], 0);

  rig.board.faults().corrupt_answers = 1;
  ExchangeStatus s = rig.driver.Exchange({200, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kCorrupted);
  EXPECT_EQ(in.pwm, held.pwm);
  EXPECT_EQ(rig.driver.counters().frames_corrupted, 1U);

  // A damaged request: the board refuses it and keeps its previous target.
  const std::int32_t before = rig.board.encoder(0).PositionAt(1'000'000'000);
  rig.board.faults().corrupt_requests = 1;
  s = rig.driver.Exchange({5000, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kCorrupted);
  EXPECT_EQ(rig.board.requests_rejected(), 1U);
  EXPECT_EQ(rig.board.encoder(0).PositionAt(1'000'000'000), before);
  EXPECT_EQ(rig.driver.counters().frames_corrupted, 2U);

  rig.board.faults().drop_answers = 1;
  s = rig.driver.Exchange({300, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kMissed);
  EXPECT_STREQ(s.reason, "no answer from the board (MISO idle)");

  rig.board.faults().delay_answers = 1;
  s = rig.driver.Exchange({300, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kMissed);
  EXPECT_EQ(rig.driver.counters().frames_missed, 2U);
  EXPECT_EQ(in.pwm, held.pwm);

  // Back to normal.
  s = rig.driver.Exchange({300, 0, 0, 0}, in);
  EXPECT_TRUE(s.ok()) << s.reason;

  // A stuck encoder emits nothing, whatever is sent.
  rig.board.faults().stick_encoder = true;
  const std::int32_t frozen = rig.board.encoder(0).PositionAt(rig.board.time_ns() + kFpgaStepNs);
  ASSERT_TRUE(rig.driver.Exchange({4000, 0, 0, 0}, in).ok());
  EXPECT_EQ(rig.board.encoder(0).PositionAt(rig.board.time_ns() + kFpgaStepNs), frozen);
  rig.board.faults().stick_encoder = false;

  // A board that lost its INIT is a fault, not a value (RESET's answer waits in the register,
  // the driver's next request transfer shifts it out unread).
  FrameBytes reset_request;
  Frame reset;
  reset.opcode = Opcode::kReset;
  ASSERT_EQ(Encode(reset, Direction::kRequest, Image::kIcoboardInverse, reset_request), FrameError::kOk);
  FrameBytes reply;
  rig.board.Exchange(reset_request, reply);
  s = rig.driver.Exchange({0, 0, 0, 0}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kFault);
  EXPECT_EQ(rig.driver.counters().faults, 1U);
}

TEST(IcoBoardInverse, ChangesBeyondThePulseLimitAreReported) {
  TwinRig rig;
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  const auto limit = static_cast<std::int32_t>(MaxCountsPerStep(kFpgaStepNs, ClockDividerForStep(kFpgaStepNs)));
  TwinInputs in;
  ExchangeStatus s = rig.driver.Exchange({limit, 0, 0, 0}, in);
  EXPECT_TRUE(s.ok());
  EXPECT_FALSE(s.pulse_limit);
  s = rig.driver.Exchange({2 * limit + 1, 0, 0, 0}, in);
  EXPECT_TRUE(s.ok());
  EXPECT_TRUE(s.pulse_limit);
  EXPECT_EQ(rig.driver.counters().counts_over_limit, 1U);
  EXPECT_EQ(rig.driver.counters().pulse_limit_events, 1U);  // the board flagged it too
  EXPECT_NE(in.board_status & kStatusPulseLimit, 0);
}

TEST(IcoBoardInverse, AHalfTurnRaisesPulseLimitEvenWhenThePeriodHasTheSubticks) {
  // 1 kHz: S = 8333 sub-ticks, yet a change of 8192 is half a turn (ambiguous in direction): the
  // board emits 8191, answers PULSE_LIMIT, and the ENC read-back shows where the period ends.
  constexpr std::int64_t kStepNs = 1'000'000;
  TwinRig rig;
  ASSERT_TRUE(rig.driver.Init(kStepNs).ok);
  ASSERT_GE(SubticksPerStep(kStepNs, rig.driver.clock_divider()), 8192U);
  TwinInputs in;
  const ExchangeStatus s = rig.driver.Exchange({-8192, 0, 0, 0}, in);
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_NE(in.board_status & kStatusPulseLimit, 0);
  EXPECT_EQ(rig.driver.counters().pulse_limit_events, 1U);
  EXPECT_EQ(rig.driver.counters().counts_over_limit, 1U);  // the driver agrees with the board
  EXPECT_EQ(rig.board.encoder(0).segment().pulses, 8191U);
  EXPECT_EQ(rig.board.encoder(0).PositionAt(2 * kStepNs), -8191);
}

TEST(IcoBoardLink, EveryDamagedRequestBitIsCountedAsCorruptedNotMissed) {
  // The board echoes a damaged request's opcode and sequence bytes in its REQUEST_REJECTED answer:
  // a flip in the sequence byte must not pass for a stale answer. The hook flips bit 0, 1, ... 95
  // on successive corrupted requests.
  TwinRig rig;
  RampSource source;
  rig.board.SetPwmSource(&source);
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  TwinInputs in;
  ASSERT_TRUE(rig.driver.Exchange({10, 20, 30, 40}, in).ok());
  ASSERT_TRUE(rig.driver.Exchange({10, 20, 30, 40}, in).ok());
  const TwinInputs held = in;
  for (std::uint32_t bit = 0; bit < kFrameBytes * 8; ++bit) {
    rig.board.faults().corrupt_requests = 1;
    const ExchangeStatus s = rig.driver.Exchange({5000, 20, 30, 40}, in);
    EXPECT_EQ(s.code, ExchangeStatus::Code::kCorrupted) << "bit " << bit << ": " << s.reason;
    EXPECT_EQ(in.pwm, held.pwm) << "bit " << bit;
  }
  EXPECT_EQ(rig.board.requests_rejected(), kFrameBytes * 8);
  EXPECT_EQ(rig.driver.counters().frames_corrupted, kFrameBytes * 8);
  EXPECT_EQ(rig.driver.counters().frames_missed, 0U);
  // No damaged request was acted upon: the emulator still heads for the last accepted target.
  EXPECT_EQ(rig.board.encoder(0).PositionAt(1'000'000'000), 10);
}

TEST(IcoBoardInverse, AFailedExchangeDoesNotMoveThePulseLimitReference) {
  TwinRig rig;
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  const auto limit = static_cast<std::int32_t>(MaxCountsPerStep(kFpgaStepNs, ClockDividerForStep(kFpgaStepNs)));
  TwinInputs in;
  rig.board.faults().corrupt_requests = 1;
  EXPECT_EQ(rig.driver.Exchange({limit, 0, 0, 0}, in).code, ExchangeStatus::Code::kCorrupted);
  EXPECT_EQ(rig.driver.counters().counts_over_limit, 0U);
  // The board never took `limit`: from its position 0, limit + 1 is over the limit.
  const ExchangeStatus s = rig.driver.Exchange({limit + 1, 0, 0, 0}, in);
  EXPECT_TRUE(s.ok()) << s.reason;
  EXPECT_TRUE(s.pulse_limit);
  EXPECT_EQ(rig.driver.counters().counts_over_limit, 1U);
  EXPECT_EQ(rig.driver.counters().pulse_limit_events, 1U);  // and the board agrees
}

TEST(IcoBoardLink, TestFrameEchoes) {
  TwinRig rig;
  std::array<std::uint8_t, 8> echo{};
  const std::array<std::uint8_t, 8> pattern = {1, 2, 3, 4, 0xF0, 0x0F, 0xAA, 0x55};
  ASSERT_TRUE(rig.driver.Test(pattern, echo).ok());  // TEST works before INIT
  EXPECT_EQ(echo, pattern);
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  TwinInputs in;
  ASSERT_TRUE(rig.driver.Exchange({1, 2, 3, 4}, in).ok());
  ASSERT_TRUE(rig.driver.Test(pattern, echo).ok());
  ASSERT_TRUE(rig.driver.Test(pattern, echo).ok());
  // Each kind is counted apart (INIT reset the counters, so the first TEST is gone).
  const LinkCounters& c = rig.driver.counters();
  EXPECT_EQ(c.test_frames_sent, 2U);
  EXPECT_EQ(c.test_frames_received, 2U);
  EXPECT_EQ(c.init_frames_sent, 1U);
  EXPECT_EQ(c.frames_sent, 1U);
  EXPECT_EQ(c.frames_received, 1U);
  // A damaged TEST answer is a link error like any other, but not a data frame.
  rig.board.faults().corrupt_answers = 1;
  EXPECT_EQ(rig.driver.Test(pattern, echo).code, ExchangeStatus::Code::kCorrupted);
  EXPECT_EQ(c.test_frames_sent, 3U);
  EXPECT_EQ(c.test_frames_received, 2U);
  EXPECT_EQ(c.frames_corrupted, 1U);
  EXPECT_EQ(c.frames_sent, 1U);
}

TEST(EmulatedFpga, PerChannelOpcodesReadOneChannelBack) {
  EmulatedFpga board(Image::kIcoboard);
  EmulatedSpiBus bus(board);
  IcoBoard ecs(bus);
  ASSERT_TRUE(ecs.Init(1'000'000).ok);
  EcsInputs in;
  ASSERT_TRUE(ecs.Exchange({100, -200, 300, -400}, in).ok());
  Frame request;
  request.opcode = PwmOpcode(1);
  request.sequence = 77;
  FrameBytes tx;
  FrameBytes rx;
  ASSERT_EQ(Encode(request, Direction::kRequest, Image::kIcoboard, tx), FrameError::kOk);
  board.Exchange(tx, rx);
  // The answer comes one transfer late: fetch it with a NOOP.
  Frame fetch;
  fetch.sequence = 78;
  ASSERT_EQ(Encode(fetch, Direction::kRequest, Image::kIcoboard, tx), FrameError::kOk);
  board.Exchange(tx, rx);
  Frame answer;
  ASSERT_EQ(Decode(rx, Direction::kAnswer, Image::kIcoboard, answer), FrameError::kOk);
  EXPECT_EQ(answer.sequence, 77);
  EXPECT_EQ(answer.pwm[1], (PwmWord{200, true, false}));
}

TEST(EmulatedFpga, EcsAndTwinBoardsWiredInOneProcess) {
  // ECS at 1 kHz, twin at 4 kHz, on one virtual timeline starting together.
  EmulatedFpga ecs_board(Image::kIcoboard);
  EmulatedFpga twin_board(Image::kIcoboardInverse);
  EmulatorToReaderLink encoder_lines(twin_board);
  GeneratorToReaderLink pwm_lines(ecs_board);
  ecs_board.SetEncoderSource(&encoder_lines);
  twin_board.SetPwmSource(&pwm_lines);
  EmulatedSpiBus ecs_bus(ecs_board);
  EmulatedSpiBus twin_bus(twin_board);
  IcoBoard ecs(ecs_bus);
  IcoBoardInverse twin(twin_bus);
  constexpr std::int64_t kEcsStep = 1'000'000;
  ASSERT_TRUE(ecs.Init(kEcsStep).ok);
  ASSERT_TRUE(twin.Init(kFpgaStepNs).ok);

  EcsInputs ecs_in;
  TwinInputs twin_in;
  std::int64_t twin_position = 0;
  for (int ms = 0; ms < 20; ++ms) {
    const std::int32_t command = ms < 5 ? 0 : 1000;
    ASSERT_TRUE(ecs.Exchange({command, 0, 0, 0}, ecs_in).ok());
    for (int k = 0; k < 4; ++k) {
      ASSERT_TRUE(twin.Exchange({static_cast<std::int32_t>(twin_position), 0, 0, 0}, twin_in).ok());
      EXPECT_EQ(twin_in.pwm[0], command);  // PWM crosses without loss
      twin_position += twin_in.pwm[0] / 100;  // a toy plant: 10 counts per twin step at 1000
    }
    if (ms < 5) {
      EXPECT_EQ(ecs_in.absolute_counts[0], 0);
    }
  }
  // The ECS reads what the twin emitted by the ECS's sampling moment: the twin's position lags
  // by the last twin period at most (pulses spread over the period that follows the sample).
  EXPECT_GT(ecs_in.absolute_counts[0], 0);
  EXPECT_LE(twin_position - ecs_in.absolute_counts[0], 2 * 4 * 10);
  EXPECT_GE(twin_position - ecs_in.absolute_counts[0], 10);
}

TEST(IcoBoard, PerCycleExchangeAllocatesNothing) {
  TwinRig rig;
  RampSource source;
  source.times.reserve(3000);
  rig.board.SetPwmSource(&source);
  ASSERT_TRUE(rig.driver.Init(kFpgaStepNs).ok);
  EmulatedFpga ecs_board(Image::kIcoboard);
  EmulatorToReaderLink lines(rig.board);  // the ECS readers decode the twin's edges
  ecs_board.SetEncoderSource(&lines);
  EmulatedSpiBus ecs_bus(ecs_board);
  IcoBoard ecs(ecs_bus);
  ASSERT_TRUE(ecs.Init(kFpgaStepNs).ok);
  TwinInputs twin_in;
  EcsInputs ecs_in;
  std::array<std::uint8_t, 8> echo{};
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount count;
    for (int k = 0; k < 2000; ++k) {
      (void)rig.driver.Exchange({k, -k, 2 * k, 0}, twin_in);
      (void)ecs.Exchange({k % 2048, 0, 0, 0}, ecs_in);
      (void)rig.driver.Test({1, 2, 3, 4, 5, 6, 7, 8}, echo);
      rig.board.faults().corrupt_answers = k % 7 == 0 ? 1U : 0U;
    }
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0U);
  EXPECT_GT(rig.driver.counters().frames_corrupted, 0U);
  EXPECT_GT(ecs_board.encoder_lines().counters().edges, 1000U);
}

}  // namespace
}  // namespace hiltwin::io
