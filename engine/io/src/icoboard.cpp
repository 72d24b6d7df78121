#include "hiltwin/io/icoboard.h"

#include <stdexcept>

#include "hiltwin/io/encoder_emulator.h"

namespace hiltwin::io {
namespace {

bool IsIdle(const FrameBytes& bytes) noexcept {
  // A board that does not drive MISO reads as all ones (pull-up) or all zeros.
  bool all_ones = true;
  bool all_zeros = true;
  for (const std::uint8_t b : bytes) {
    all_ones = all_ones && b == 0xFF;
    all_zeros = all_zeros && b == 0x00;
  }
  return all_ones || all_zeros;
}

const char* DecodeReason(FrameError error) noexcept {
  switch (error) {
    case FrameError::kChecksum: return "answer failed its CRC-8 check";
    case FrameError::kOpcode: return "answer carries an unknown opcode";
    case FrameError::kReservedBits: return "answer has reserved bits set";
    case FrameError::kOutOfRange: return "answer has a field out of range";
    case FrameError::kOk: break;
  }
  return "";
}

/// The sent and received counters of the kind of frame `opcode` starts.
struct KindCounters {
  std::uint64_t* sent;
  std::uint64_t* received;
};
KindCounters CountersOfKind(LinkCounters& counters, Opcode opcode) noexcept {
  switch (opcode) {
    case Opcode::kInit: return {&counters.init_frames_sent, &counters.init_frames_received};
    case Opcode::kTest: return {&counters.test_frames_sent, &counters.test_frames_received};
    default: return {&counters.frames_sent, &counters.frames_received};
  }
}

const char* SideName(Image image) noexcept {
  return image == Image::kIcoboard ? "the ECS" : "the twin";
}

}  // namespace

const char* ToString(ExchangeStatus::Code code) noexcept {
  switch (code) {
    case ExchangeStatus::Code::kOk: return "ok";
    case ExchangeStatus::Code::kCorrupted: return "corrupted";
    case ExchangeStatus::Code::kMissed: return "missed";
    case ExchangeStatus::Code::kFault: return "fault";
  }
  return "?";
}

IcoBoardLink::IcoBoardLink(SpiBus& bus, Image image, const kernel_glue::Clock* clock) noexcept
    : spi_(bus, clock), image_(image) {}

ExchangeStatus IcoBoardLink::Transact(Frame& request, Frame& answer) noexcept {
  request.sequence = ++sequence_;
  const bool encoded = Encode(request, Direction::kRequest, image_, tx_) == FrameError::kOk;
  if (!EncodeFetch() || !encoded) return EncodeFault();
  return TransferAndCheck(request.opcode, [&] { return CheckAnswer(request, answer); });
}

ExchangeStatus IcoBoardLink::TransactAll(ChannelWords words, AllFrame& answer) noexcept {
  const AllFrame request{++sequence_, 0, words};
  const bool encoded = EncodeAll(request, Direction::kRequest, image_, tx_) == FrameError::kOk;
  if (!EncodeFetch() || !encoded) return EncodeFault();
  return TransferAndCheck(Opcode::kAll, [&] { return CheckAllAnswer(request.sequence, answer); });
}

bool IcoBoardLink::EncodeFetch() noexcept {
  // The fetch: a NOOP with its own sequence number, whose transfer carries the answer to the
  // request in tx_ (the board answers one transfer late; docs/spi-protocol.md, "Pipelined
  // answers").
  EncodeNoop(++sequence_, 0, fetch_tx_);
  return true;
}

ExchangeStatus IcoBoardLink::EncodeFault() noexcept {
  ++counters_.faults;
  ExchangeStatus status;
  status.code = ExchangeStatus::Code::kFault;
  status.reason = "request field out of range (driver bug)";
  return status;
}

template <typename Check>
ExchangeStatus IcoBoardLink::TransferAndCheck(Opcode opcode, Check&& check) noexcept {
  ExchangeStatus status;
  const KindCounters kind = CountersOfKind(counters_, opcode);
  ++*kind.sent;
  // The request transfer's MISO answers the previous exchange's fetch: no information.
  const TransferStatus transfer = spi_.TransferPair(tx_, request_rx_, fetch_tx_, rx_);
  status.transfer_ns = transfer.duration_ns;
  // INIT configures this side's own board, which answered; a wire peer whose heartbeat is stale
  // right now (hung, or just restarting) does not make that answer invalid. The first data
  // exchange reports the peer as a fault if it is still gone, so nothing is hidden.
  const bool peer_lost_at_init =
      transfer.result == BusResult::kPeerLost && opcode == Opcode::kInit;
  // A lost wire peer is a fault, but this side's own board still took the request: the
  // answer is checked all the same, so a caller can tell that its safe outputs arrived.
  // A corrupted wire is the same kind of fault, at INIT too: nothing read from it is trusted.
  const bool peer_lost = (transfer.result == BusResult::kPeerLost && !peer_lost_at_init) ||
                         transfer.result == BusResult::kWireCorrupted ||
                         transfer.result == BusResult::kPeerMismatch;
  if (transfer.result == BusResult::kIoError) {
    ++counters_.faults;
    status.code = ExchangeStatus::Code::kFault;
    status.reason = transfer.reason;
    return status;
  }
  status.peer_absent = transfer.result == BusResult::kPeerAbsent || peer_lost_at_init;
  if (transfer.result == BusResult::kPeerStopped) status.peer_stopped = transfer.reason;
  const ExchangeStatus checked = check();
  if (!checked.ok()) {
    status.code = checked.code;
    status.reason = checked.reason;
    return status;
  }
  status.board_answered = true;
  if (peer_lost) {
    ++counters_.faults;
    status.code = ExchangeStatus::Code::kFault;
    status.reason = transfer.reason;
    return status;
  }
  ++*kind.received;
  return status;
}

ExchangeStatus IcoBoardLink::CheckAllAnswer(std::uint8_t sequence, AllFrame& answer) noexcept {
  // Anything but an ALL frame fails a check of the general path (idle, damaged, rejected, stale
  // or another opcode): judged there, with the same counters and reasons.
  if (rx_[0] != static_cast<std::uint8_t>(Opcode::kAll)) {
    request_.opcode = Opcode::kAll;
    request_.sequence = sequence;
    return CheckAnswer(request_, answer_);
  }
  // Byte 0 is 3: the MISO is not idle (all zeros or all ones).
  const FrameError error = DecodeAll(rx_, Direction::kAnswer, image_, answer);
  return Judge(error, answer.status, answer.sequence == sequence, true, true);
}

ExchangeStatus IcoBoardLink::CheckAnswer(const Frame& request, Frame& answer) noexcept {
  if (IsIdle(rx_)) {
    ++counters_.frames_missed;
    ExchangeStatus status;
    status.code = ExchangeStatus::Code::kMissed;
    status.reason = "no answer from the board (MISO idle)";
    return status;
  }
  const FrameError error = Decode(rx_, Direction::kAnswer, image_, answer);
  const bool data = request.opcode != Opcode::kInit && request.opcode != Opcode::kTest &&
                    request.opcode != Opcode::kNoop && request.opcode != Opcode::kReset;
  return Judge(error, answer.status, answer.sequence == request.sequence,
               answer.opcode == request.opcode, data);
}

ExchangeStatus IcoBoardLink::Judge(FrameError error, std::uint8_t answer_status,
                                   bool same_sequence, bool same_opcode, bool data) noexcept {
  ExchangeStatus status;
  if (error != FrameError::kOk) {
    ++counters_.frames_corrupted;
    status.code = ExchangeStatus::Code::kCorrupted;
    status.reason = DecodeReason(error);
    return status;
  }
  // Rejection first: the board echoes the damaged request's opcode and sequence bytes, so a flip
  // there must not read as a stale answer or an answer to another opcode.
  if ((answer_status & kStatusRequestRejected) != 0) {
    ++counters_.frames_corrupted;
    status.code = ExchangeStatus::Code::kCorrupted;
    status.reason = "the board rejected the request (damaged on the way)";
    return status;
  }
  if (!same_sequence) {
    ++counters_.frames_missed;
    status.code = ExchangeStatus::Code::kMissed;
    status.reason = "stale answer (sequence number of an earlier request)";
    return status;
  }
  if (!same_opcode) {
    ++counters_.frames_corrupted;
    status.code = ExchangeStatus::Code::kCorrupted;
    status.reason = "answer to a different opcode";
    return status;
  }
  if (data && (answer_status & kStatusInitialised) == 0) {
    ++counters_.faults;
    status.code = ExchangeStatus::Code::kFault;
    status.reason = "the board is not initialised (reset or power loss): run INIT again";
    return status;
  }
  return status;
}

InitResult IcoBoardLink::Init(std::int64_t step_ns) {
  if (step_ns < kNsPerFpgaClock || step_ns > 0xFFFF'FFFFLL) {
    throw std::invalid_argument("INIT step " + std::to_string(step_ns) +
                                " ns is outside [10 ns, 4294967295 ns]: choose a rate between "
                                "0.24 Hz and 100 MHz");
  }
  counters_ = LinkCounters{};
  initialised_ = false;
  // The board starts from position 0 after INIT; so do the change checks and unwrappers.
  last_counts_.fill(0);
  for (auto& unwrapper : unwrappers_) unwrapper.Reset();
  InitResult result;
  const std::uint32_t divider =
      image_ == Image::kIcoboardInverse ? ClockDividerForStep(step_ns) : 0;
  ExchangeStatus status;
  for (int attempt = 0; attempt < 3; ++attempt) {
    request_ = Frame{};
    request_.opcode = Opcode::kInit;
    request_.init_request = InitRequest{static_cast<std::uint32_t>(step_ns), divider};
    status = Transact(request_, answer_);
    if (status.ok() || status.code == ExchangeStatus::Code::kFault) break;
  }
  if (!status.ok()) {
    result.message = std::string("Failed to initialise FPGA: no valid answer to INIT over ") +
                     spi_.bus().Name() + " (" + status.reason +
                     "); check the cable, power and that the FPGA is programmed";
    return result;
  }
  const InitAnswer& init = answer_.init_answer;
  result.identity = init.identity;
  const auto found = ImageOfIdentity(init.identity);
  result.image_known = found.has_value();
  if (found) result.found = *found;
  if (!found || *found != image_) {
    const std::string found_text =
        found ? std::string(ToString(*found))
              : "an unknown image (identity " + std::to_string(init.identity) + ")";
    result.message = "Failed to initialise FPGA: found " + found_text + ", " + SideName(image_) +
                     " needs " + ToString(image_) + " (program " + ToString(image_) +
                     " onto this board, or swap the boards)";
    return result;
  }
  if (init.protocol_version != kProtocolVersion || init.channels != kChannels) {
    result.message = "Failed to initialise FPGA: protocol version " +
                     std::to_string(init.protocol_version) + " with " +
                     std::to_string(init.channels) + " channels, hiltwin speaks version " +
                     std::to_string(kProtocolVersion) + " with 4; update the FPGA image";
    return result;
  }
  if ((answer_.status & kStatusInitRejected) != 0 || (answer_.status & kStatusInitialised) == 0) {
    result.message = "Failed to initialise FPGA: the board rejected step " +
                     std::to_string(step_ns) + " ns with clock divider " +
                     std::to_string(divider) + "; choose a longer step";
    return result;
  }
  result.ok = true;
  result.clock_divider = init.clock_divider;
  initialised_ = true;
  step_ns_ = step_ns;
  clock_divider_ = init.clock_divider;
  counts_limit_ = MaxCountsPerStep(step_ns_, clock_divider_);
  return result;
}

ExchangeStatus IcoBoardLink::Test(const std::array<std::uint8_t, 8>& pattern,
                                  std::array<std::uint8_t, 8>& echo) noexcept {
  request_.opcode = Opcode::kTest;
  request_.raw = pattern;
  const ExchangeStatus status = Transact(request_, answer_);
  if (status.ok()) echo = answer_.raw;
  return status;
}

ExchangeStatus IcoBoardInverse::Exchange(
    const std::array<std::int32_t, kChannels>& encoder_counts_out, TwinInputs& in) noexcept {
  bool over_limit = false;
  ChannelWords words = 0;
  // |change| > limit as one unsigned comparison: |change| < 2^33 and 0 <= limit < 2^14.
  const auto limit_span = 2 * static_cast<std::uint64_t>(counts_limit_);
  for (std::size_t c = 0; c < kChannels; ++c) {
    const std::int64_t counts = encoder_counts_out[c];
    const std::int64_t change = counts - last_counts_[c];
    if (static_cast<std::uint64_t>(change + counts_limit_) > limit_span) {
      ++counters_.counts_over_limit;
      over_limit = true;
    }
    const EncWord word{static_cast<std::int16_t>(WrapToRelative(counts)), pins_out_[c]};
    words = (words << 16U) | PackEnc(word);  // channel 0 ends in the top lane
  }
  AllFrame answer;
  ExchangeStatus status = TransactAll(words, answer);
  status.pulse_limit = over_limit;
  if (!status.ok()) return status;
  // Only an acknowledged request is known to have moved the board's target; after a failed one
  // the next change is still measured from the last position the board confirmed.
  for (std::size_t c = 0; c < kChannels; ++c) last_counts_[c] = encoder_counts_out[c];
  ChannelWords rest = answer.words;  // channel 0 in the top lane, shifted out first
  for (std::size_t c = 0; c < kChannels; ++c) {
    const auto word = static_cast<std::uint16_t>(rest >> 48U);
    rest <<= 16U;
    in.pwm[c] = PwmValueOfWord(word);
    in.duty[c] = PwmToDuty(in.pwm[c]);
    in.pins[c] = WordPin(word);
  }
  in.board_status = answer.status;
  if ((answer.status & kStatusPulseLimit) != 0) {
    ++counters_.pulse_limit_events;
    status.pulse_limit = true;
  }
  return status;
}

ExchangeStatus IcoBoard::Exchange(const std::array<std::int32_t, kChannels>& pwm_out,
                                  EcsInputs& in) noexcept {
  ChannelWords words = 0;
  for (std::size_t c = 0; c < kChannels; ++c) {
    std::int32_t value = pwm_out[c];
    if (value < kPwmValueMin) value = kPwmValueMin;
    if (value > kPwmValueMax) value = kPwmValueMax;
    words |= PlaceChannelWord(c, PackPwm(PwmWordFromValue(value, pins_out_[c])));
  }
  AllFrame answer;
  const ExchangeStatus status = TransactAll(words, answer);
  if (!status.ok()) return status;
  for (std::size_t c = 0; c < kChannels; ++c) {
    const EncWord word = UnpackEnc(ChannelWord(answer.words, c));
    in.counts[c] = word.counts;
    in.absolute_counts[c] = unwrappers_[c].Update(in.counts[c]);
    in.pins[c] = word.pin;
  }
  in.board_status = answer.status;
  return status;
}

}  // namespace hiltwin::io
