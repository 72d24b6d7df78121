#include "hiltwin/io/board_pair_check.h"

#include <algorithm>

namespace hiltwin::io {
namespace {

/// Where channel c oscillates: on an encoder wrap (absolute (2m + 1)·8192, where the 14-bit
/// position jumps from 8191 to −8192), on both sides of zero and on the first and second wrap.
constexpr std::array<std::int32_t, kChannels> kWrapCentres = {8192, -8192, 3 * 8192, -3 * 8192};
/// Counts per frame while walking, channel 0; channel c walks (c + 1) times as fast.
constexpr std::int32_t kWalkCounts = 13;

}  // namespace

EncoderTestPattern::EncoderTestPattern(std::uint32_t max_counts_per_step) noexcept
    // At least 2, so the walk has a bottom below the wrap and a top above it.
    : limit_(static_cast<std::int32_t>(std::clamp<std::uint32_t>(max_counts_per_step, 2, 8191))) {
  for (std::size_t c = 0; c < kChannels; ++c) {
    Channel& channel = channels_[c];
    channel.bottom = kWrapCentres[c] - limit_ / 2;
    channel.top = channel.bottom + limit_;
    channel.walk = std::min(limit_, kWalkCounts * static_cast<std::int32_t>(c + 1));
  }
}

const std::array<std::int32_t, kChannels>& EncoderTestPattern::Next() noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) positions_[c] = Advance(channels_[c], positions_[c]);
  return positions_;
}

std::int32_t EncoderTestPattern::Advance(Channel& ch, std::int32_t position) const noexcept {
  switch (ch.phase) {
    case Phase::kApproach: {  // from 0 at INIT to the bottom, at the limit
      const std::int32_t gap = ch.bottom - position;
      const std::int32_t move = std::clamp(gap, -limit_, limit_);
      if (move == gap) ch.phase = Phase::kWalkUp;
      return position + move;
    }
    case Phase::kWalkUp: {
      const std::int32_t next = std::min(ch.top, position + ch.walk);
      if (next == ch.top) ch.phase = Phase::kStopTop;
      return next;
    }
    case Phase::kStopTop:
      ch.phase = Phase::kJumpDown;
      return position;
    case Phase::kJumpDown:
      ch.phase = Phase::kJumpUp;
      return ch.bottom;  // −limit
    case Phase::kJumpUp:
      ch.phase = Phase::kWalkDown;
      return ch.top;  // +limit
    case Phase::kWalkDown: {
      const std::int32_t next = std::max(ch.bottom, position - ch.walk);
      if (next == ch.bottom) ch.phase = Phase::kStopBottom;
      return next;
    }
    case Phase::kStopBottom:
      ch.phase = Phase::kWalkUp;
      return position;
  }
  return position;
}

std::int32_t PwmTestValue(std::int64_t k, std::size_t c) noexcept {
  return static_cast<std::int32_t>((k * 37 + static_cast<std::int64_t>(c) * 511) % 4095) - 2047;
}

const char* PairStatus::fault() const noexcept {
  if (ecs.code == ExchangeStatus::Code::kFault) return ecs.reason;
  if (twin.code == ExchangeStatus::Code::kFault) return twin.reason;
  return nullptr;
}

BoardPairCheck::BoardPairCheck(Image twin_board_image, Image ecs_board_image) noexcept
    : twin_board_(twin_board_image), ecs_board_(ecs_board_image) {
  ecs_board_.SetEncoderSource(&encoder_wires_);
  twin_board_.SetPwmSource(&pwm_wires_);
}

PairInit BoardPairCheck::Init(std::int64_t step_ns) {
  PairInit result;
  // The twin first: its INIT starts the emulator's first period, which the ECS's INIT then
  // loads as the lines' resting position.
  result.twin = twin_.Init(step_ns);
  result.ecs = ecs_.Init(step_ns);
  pattern_ = EncoderTestPattern(MaxCountsPerStep(step_ns, twin_.clock_divider()));
  step_ = 0;
  encoder_sent_.fill(0);
  tally_ = PairTally{};
  return result;
}

void BoardPairCheck::ApplyFault() noexcept {
  const bool active = step_ >= fault_.at_frame && step_ < fault_.at_frame + fault_.frames;
  twin_board_.faults().stick_encoder = active && fault_.kind == LinkFault::Kind::kStuckEmulator;
  ecs_board_.faults().stick_encoder = active && fault_.kind == LinkFault::Kind::kStuckReader;
  if (active && fault_.kind == LinkFault::Kind::kCorruptCounts) {
    ecs_board_.faults().corrupt_answers = 1;
  }
}

PairStatus BoardPairCheck::DataStep() noexcept {
  ApplyFault();
  PairStatus status;
  for (std::size_t c = 0; c < kChannels; ++c) pwm_out_[c] = PwmTestValue(step_, c);
  status.ecs = ecs_.Exchange(pwm_out_, ecs_in_);
  ++tally_.pwm.sent;
  // The ECS's first frame reads the lines at rest after INIT: no message is due yet.
  if (step_ > 0) CheckEncoder(status.ecs, step_ - 1, encoder_sent_);
  encoder_sent_ = pattern_.Next();
  status.twin = twin_.Exchange(encoder_sent_, twin_in_);
  ++tally_.encoder.sent;
  CheckPwm(status.twin, step_, pwm_out_);
  CountWraps();
  ++step_;
  return status;
}

PairStatus BoardPairCheck::TestStep(const std::array<std::uint8_t, 8>& pattern) noexcept {
  PairStatus status;
  std::array<std::uint8_t, 8> echo{};
  status.ecs = ecs_.Test(pattern, echo);
  if (status.ecs.ok() && echo != pattern) ++tally_.test_echo_errors;
  echo.fill(0);
  status.twin = twin_.Test(pattern, echo);
  if (status.twin.ok() && echo != pattern) ++tally_.test_echo_errors;
  return status;
}

PairStatus BoardPairCheck::Finish() noexcept {
  ApplyFault();
  PairStatus status;
  pwm_out_.fill(0);
  status.ecs = ecs_.Exchange(pwm_out_, ecs_in_);
  if (step_ > 0) CheckEncoder(status.ecs, step_ - 1, encoder_sent_);
  return status;
}

void BoardPairCheck::CheckEncoder(const ExchangeStatus& status, std::int64_t frame,
                                  const std::array<std::int32_t, kChannels>& sent) noexcept {
  FirstMiss& first = tally_.first_encoder_miss;
  if (!status.ok()) {
    if (first.frame < 0) {
      first = FirstMiss{frame, 0, sent[0], ecs_in_.absolute_counts[0], status.reason};
    }
    return;
  }
  for (std::size_t c = 0; c < kChannels; ++c) {
    // Both what the ECS board's register holds and what the driver unwrapped from it.
    if (ecs_in_.absolute_counts[c] != sent[c] || ecs_in_.counts[c] != WrapToRelative(sent[c])) {
      ++tally_.encoder.wrong;
      if (first.frame < 0) first = FirstMiss{frame, c, sent[c], ecs_in_.absolute_counts[c], ""};
      return;
    }
  }
  ++tally_.encoder.received;
}

void BoardPairCheck::CheckPwm(const ExchangeStatus& status, std::int64_t frame,
                              const std::array<std::int32_t, kChannels>& sent) noexcept {
  FirstMiss& first = tally_.first_pwm_miss;
  if (!status.ok()) {
    if (first.frame < 0) first = FirstMiss{frame, 0, sent[0], twin_in_.pwm[0], status.reason};
    return;
  }
  for (std::size_t c = 0; c < kChannels; ++c) {
    if (twin_in_.pwm[c] != sent[c]) {
      ++tally_.pwm.wrong;
      if (first.frame < 0) first = FirstMiss{frame, c, sent[c], twin_in_.pwm[c], ""};
      return;
    }
  }
  ++tally_.pwm.received;
}

void BoardPairCheck::CountWraps() noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const EncoderEmulator& emulator = twin_board_.encoder(c);
    if (emulator.segment().pulses == 0) continue;  // no period of this channel moved
    if (emulator.last_case() == DifferenceCase::kD) ++tally_.wraps_up;
    if (emulator.last_case() == DifferenceCase::kC) ++tally_.wraps_down;
  }
}

}  // namespace hiltwin::io
