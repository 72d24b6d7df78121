#include "hiltwin/io/emulated_fpga.h"

#include <bit>

#include "hiltwin/io/conversions.h"

namespace hiltwin::io {
namespace {
constexpr std::uint32_t kFrameBits = static_cast<std::uint32_t>(kFrameBytes * 8);
}  // namespace

EmulatedFpga::EmulatedFpga(Image image, const kernel_glue::Clock* clock) noexcept
    : image_(image), clock_(clock) {}

void EmulatedFpga::ResetState() noexcept {
  initialised_ = false;
  pulse_limit_ = false;
  step_ns_ = 0;
  divider_ = 0;
  time_ns_ = 0;
  data_frames_ = 0;
  for (auto& emulator : emulators_) emulator.Reset();
  pwm_values_.fill(0);
  pwm_memo_valid_ = false;
  counts_.fill(0);
  pins_out_.fill(false);
  lines_.Reset();
}

void EmulatedFpga::PublishPeriod() noexcept {
  if (encoder_sink_ == nullptr) return;
  for (std::size_t c = 0; c < kChannels; ++c) period_scratch_[c] = emulators_[c].segment();
  encoder_sink_->OnPeriod(period_scratch_);
}

void EmulatedFpga::Exchange(const FrameBytes& mosi, FrameBytes& miso) noexcept {
  // Transfer n shifts out the answer to request n-1 (the register as it stood when CS fell);
  // the request arriving in it is acted upon at its end.
  SendAnswer(miso);
  TakeRequest(mosi);
}

void EmulatedFpga::SendAnswer(FrameBytes& miso) noexcept {
  miso = answer_register_;
  // Answer faults skip the answers to NOOPs (the driver's fetches, whose answers nobody reads).
  if (answer_register_data_) {
    if (faults_.delay_answers > 0) {
      --faults_.delay_answers;
      miso = previous_miso_;
    } else if (faults_.drop_answers > 0) {
      --faults_.drop_answers;
      miso.fill(0xFF);
    } else if (faults_.corrupt_answers > 0) {
      --faults_.corrupt_answers;
      const std::uint32_t bit = corrupt_bit_++ % kFrameBits;
      miso[bit / 8] = static_cast<std::uint8_t>(miso[bit / 8] ^ (1U << (bit % 8)));
    }
  }
  previous_miso_ = miso;
}

void EmulatedFpga::TakeRequest(const FrameBytes& mosi) noexcept {
  if (IsNoopRequest(mosi)) {
    // The driver's fetch (no request fault applies to a NOOP): what Decode, HandleRequest and
    // Encode give for a valid NOOP.
    answer_register_data_ = false;
    EncodeNoop(mosi[1], WithStateBits(0), answer_register_);
    return;
  }
  const bool data = mosi[0] != static_cast<std::uint8_t>(Opcode::kNoop);
  answer_register_data_ = data;
  if (data && faults_.corrupt_requests > 0) {
    --faults_.corrupt_requests;
    FrameBytes damaged = mosi;
    const std::uint32_t bit = corrupt_bit_++ % kFrameBits;
    damaged[bit / 8] = static_cast<std::uint8_t>(damaged[bit / 8] ^ (1U << (bit % 8)));
    ActOn(damaged);
  } else {
    ActOn(mosi);
  }
}

void EmulatedFpga::ActOn(const FrameBytes& request_bytes) noexcept {
  if (request_bytes[0] == static_cast<std::uint8_t>(Opcode::kAll)) {
    TakeAll(request_bytes);
    return;
  }
  Frame request;
  Frame answer;
  if (Decode(request_bytes, Direction::kRequest, image_, request) != FrameError::kOk) {
    Reject(request_bytes);
    return;
  }
  HandleRequest(request, answer);
  answer.status = WithStateBits(answer.status);
  if (Encode(answer, Direction::kAnswer, image_, answer_register_) != FrameError::kOk) {
    answer_register_.fill(0xFF);  // cannot happen for values the model produces; fail visibly
  }
}

void EmulatedFpga::TakeAll(const FrameBytes& request_bytes) noexcept {
  // The per-cycle frame, word-wide: no Frame between the bytes and the board.
  AllFrame request;
  if (DecodeAll(request_bytes, Direction::kRequest, image_, request) != FrameError::kOk) {
    Reject(request_bytes);
    return;
  }
  AllFrame answer{request.sequence, 0, 0};
  if (initialised_) answer.words = HandleAll(request.words);  // else zeros, no kStatusInitialised
  answer.status = WithStateBits(0);
  if (EncodeAll(answer, Direction::kAnswer, image_, answer_register_) != FrameError::kOk) {
    answer_register_.fill(0xFF);  // cannot happen for values the model produces; fail visibly
  }
}

void EmulatedFpga::Reject(const FrameBytes& request_bytes) noexcept {
  // Never act on a damaged request: hold every output, say so in the status byte.
  ++requests_rejected_;
  Frame answer;
  const std::uint8_t op = request_bytes[0];
  answer.opcode = op <= static_cast<std::uint8_t>(Opcode::kTest) ? static_cast<Opcode>(op)
                                                                 : Opcode::kNoop;
  answer.sequence = request_bytes[1];
  answer.status = WithStateBits(kStatusRequestRejected);
  if (Encode(answer, Direction::kAnswer, image_, answer_register_) != FrameError::kOk) {
    answer_register_.fill(0xFF);
  }
}

std::uint8_t EmulatedFpga::WithStateBits(std::uint8_t status) const noexcept {
  if (initialised_) status = static_cast<std::uint8_t>(status | kStatusInitialised);
  if (pulse_limit_) status = static_cast<std::uint8_t>(status | kStatusPulseLimit);
  return status;
}

void EmulatedFpga::HandleRequest(const Frame& request, Frame& answer) noexcept {
  answer.opcode = request.opcode;
  answer.sequence = request.sequence;
  switch (request.opcode) {
    case Opcode::kNoop: break;
    case Opcode::kInit: HandleInit(request, answer); break;
    case Opcode::kReset: ResetState(); break;
    case Opcode::kAll: break;  // TakeAll
    case Opcode::kTest: answer.raw = request.raw; break;
    default: FillReadback(request.opcode, answer); break;
  }
}

void EmulatedFpga::HandleInit(const Frame& request, Frame& answer) noexcept {
  ResetState();
  const auto step_ns = static_cast<std::int64_t>(request.init_request.step_ns);
  const std::uint32_t divider = request.init_request.clock_divider;
  bool accepted = step_ns >= kNsPerFpgaClock;
  if (accepted && image_ == Image::kIcoboardInverse) {
    for (auto& emulator : emulators_) accepted = accepted && emulator.Configure(step_ns, divider);
  }
  const Image identity_image = faults_.answer_as_image.value_or(image_);
  answer.init_answer = InitAnswer{kProtocolVersion, static_cast<std::uint8_t>(kChannels),
                                  IdentityOf(identity_image), 0};
  if (!accepted) {
    answer.status = kStatusInitRejected;
    return;
  }
  initialised_ = true;
  step_ns_ = step_ns;
  divider_ = image_ == Image::kIcoboardInverse ? divider : 0;
  answer.init_answer.clock_divider = divider_;
  time_ns_ = clock_ != nullptr ? clock_->NowNs() : 0;
  for (auto& emulator : emulators_) emulator.StartPeriod(0, time_ns_);
  if (image_ == Image::kIcoboardInverse) PublishPeriod();
}

ChannelWords EmulatedFpga::HandleAll(ChannelWords request_words) noexcept {
  const std::int64_t t_ns =
      clock_ != nullptr ? clock_->NowNs() : static_cast<std::int64_t>(data_frames_) * step_ns_;
  ++data_frames_;
  time_ns_ = t_ns;
  return image_ == Image::kIcoboardInverse ? SampleTwin(request_words, t_ns)
                                           : SampleEcs(request_words, t_ns);
}

ChannelWords EmulatedFpga::SampleTwin(ChannelWords encoder_words, std::int64_t t_ns) noexcept {
  bool limited = false;
  const bool stuck = faults_.stick_encoder;
  ChannelWords rest = encoder_words;  // channel 0 in the top lane, shifted out first
  for (std::size_t c = 0; c < kChannels; ++c) {
    const auto word = static_cast<std::uint16_t>(rest >> 48U);
    rest <<= 16U;
    emulators_[c].SetStuck(stuck);
    limited = !emulators_[c].StartPeriod(EncCountsOfWord(word), t_ns) || limited;
    pins_out_[c] = WordPin(word);
  }
  pulse_limit_ = limited;
  PublishPeriod();
  duty_scratch_.fill(0.0);
  if (pwm_source_ != nullptr) pwm_source_->DutyAt(t_ns, duty_scratch_);
  // Exact memoisation: the reader's values and the answer's words are functions of the four
  // duties and the input pins alone; with duties bit-identical to the previous frame's (and the
  // pins unchanged: SetDigitalInputs clears pwm_memo_valid_), they are the ones already held.
  std::uint64_t changed = pwm_memo_valid_ ? 0 : 1;
  for (std::size_t c = 0; c < kChannels; ++c) {
    changed |= std::bit_cast<std::uint64_t>(duty_scratch_[c]) ^ duty_bits_[c];
  }
  if (changed != 0) MeasurePwm();
  return pwm_words_;
}

void EmulatedFpga::MeasurePwm() noexcept {
  ChannelWords pwm_words = 0;
  for (std::size_t c = 0; c < kChannels; ++c) {
    duty_bits_[c] = std::bit_cast<std::uint64_t>(duty_scratch_[c]);
    pwm_values_[c] = PwmReaderValue(duty_scratch_[c]);
    pwm_words = (pwm_words << 16U) | PackPwm(PwmWordFromValue(pwm_values_[c], pins_in_[c]));
  }
  pwm_words_ = pwm_words;  // channel 0 in the top lane
  pwm_memo_valid_ = true;
}

ChannelWords EmulatedFpga::SampleEcs(ChannelWords pwm_words, std::int64_t t_ns) noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const PwmWord word = UnpackPwm(ChannelWord(pwm_words, c));
    pwm_values_[c] = PwmValueFromWord(word);
    pins_out_[c] = word.pin;
  }
  if (encoder_source_ != nullptr) {
    lines_.Update(*encoder_source_, t_ns, faults_.stick_encoder);
    for (std::size_t c = 0; c < kChannels; ++c) counts_[c] = lines_.relative_counts(c);
  }
  ChannelWords encoder_words = 0;
  for (std::size_t c = 0; c < kChannels; ++c) {
    const EncWord word{static_cast<std::int16_t>(counts_[c]), pins_in_[c]};
    encoder_words |= PlaceChannelWord(c, PackEnc(word));
  }
  return encoder_words;
}

void EmulatedFpga::FillReadback(Opcode opcode, Frame& answer) const noexcept {
  const auto c = static_cast<std::size_t>(opcode) & 3U;
  const bool twin = image_ == Image::kIcoboardInverse;
  if (static_cast<unsigned>(opcode) < 8) {
    answer.pwm[c] = PwmWordFromValue(pwm_values_[c], twin ? pins_in_[c] : pins_out_[c]);
  } else if (twin) {
    // Where the emulator will be at the end of the current period: the accepted target.
    answer.enc[c] = EncWord{static_cast<std::int16_t>(emulators_[c].PositionAt(time_ns_ + step_ns_)),
                            pins_out_[c]};
  } else {
    answer.enc[c] = EncWord{static_cast<std::int16_t>(counts_[c]), pins_in_[c]};
  }
}

void GeneratorToReaderLink::DutyAt(std::int64_t /*t_ns*/,
                                   std::array<double, kChannels>& duty_out) noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) duty_out[c] = PwmToDuty(ecs_.pwm_output()[c]);
}

}  // namespace hiltwin::io
