#include "hiltwin/fpga_sim/verilated_board.h"

#include <algorithm>
#include <cmath>

#include "hiltwin/io/conversions.h"

namespace hiltwin::fpga_sim {

VerilatedBoardDevice::VerilatedBoardDevice(RtlBench& bench, io::Image image,
                                           const DeviceTiming& timing,
                                           const kernel_glue::Clock* clock) noexcept
    : bench_(bench),
      image_(image),
      slot_(image == io::Image::kIcoboardInverse ? Slot::kTwin : Slot::kEcs),
      timing_(timing),
      clock_(clock) {}

void VerilatedBoardDevice::SetDigitalInputs(const std::array<bool, io::kChannels>& pins) noexcept {
  std::uint8_t bits = 0;
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    if (pins[c]) bits = static_cast<std::uint8_t>(bits | (1U << c));
  }
  bench_.SetPinInputs(slot_, bits);
}

void VerilatedBoardDevice::Track(const io::FrameBytes& mosi) noexcept {
  target_ps_ = bench_.now_ps();
  if (clock_ != nullptr) target_ps_ = (clock_->NowNs() + timing_.phase_ns) * 1000;
  io::Frame request;
  if (io::Decode(mosi, io::Direction::kRequest, image_, request) != io::FrameError::kOk) return;
  switch (request.opcode) {
    case io::Opcode::kInit:
      initialised_ = true;
      origin_known_ = false;
      bench_.ResetOrigin();
      step_ns_ = static_cast<std::int64_t>(request.init_request.step_ns);
      data_frames_ = 0;
      time_ns_ = 0;
      break;
    case io::Opcode::kReset: initialised_ = false; break;
    case io::Opcode::kAll:
      if (!initialised_) break;
      if (!origin_known_) {
        origin_ps_ = bench_.Origin();
        origin_known_ = true;
      }
      time_ns_ = clock_ != nullptr ? clock_->NowNs()
                                   : static_cast<std::int64_t>(data_frames_) * step_ns_;
      ++data_frames_;
      if (clock_ == nullptr) {
        const std::int64_t at_ns =
            timing_.all_interval_ns > 0
                ? static_cast<std::int64_t>(data_frames_ - 1) * timing_.all_interval_ns
                : time_ns_;
        target_ps_ = origin_ps_ + (at_ns + timing_.phase_ns) * 1000;
      }
      ApplyPwmSource();
      PullEncoderPeriods();
      break;
    default: break;
  }
}

void VerilatedBoardDevice::ApplyPwmSource() noexcept {
  if (slot_ != Slot::kTwin || bench_.wired()) return;
  duty_.fill(0.0);
  if (pwm_source_ != nullptr) pwm_source_->DutyAt(time_ns_, duty_);
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    const double duty = std::isnan(duty_[c]) ? 0.0 : duty_[c];
    const double magnitude = std::min(std::fabs(duty), 1.0);
    const auto high = static_cast<std::uint32_t>(std::nearbyint(magnitude * io::kPwmPeriodClocks));
    bench_.SetPwmInput(c, high, duty < 0.0);
  }
}

void VerilatedBoardDevice::PullEncoderPeriods() noexcept {
  if (slot_ != Slot::kEcs || bench_.wired() || encoder_source_ == nullptr) return;
  const io::LineView view = encoder_source_->Lines(time_ns_);
  // At the first ALL after INIT only the newest period counts (the lines' power-up position).
  std::uint64_t index = data_frames_ == 1 && view.newest > 0 ? view.newest : periods_pulled_ + 1;
  const std::int64_t origin_clock = origin_ps_ / kClockPs + timing_.phase_ns / io::kNsPerFpgaClock +
                                    timing_.line_delay_clocks;
  for (; index <= view.newest; ++index) {
    if (!encoder_source_->Period(index, period_scratch_)) continue;
    for (std::size_t c = 0; c < io::kChannels; ++c) {
      const io::PulseSegment& s = period_scratch_.channels[c];
      const std::int64_t start = origin_clock + s.start_ns / io::kNsPerFpgaClock;
      bench_.QueueEncoderPeriod(c, static_cast<std::uint64_t>(std::max<std::int64_t>(start, 0)),
                                s.start_counts, s.pulses, s.direction, s.subticks, s.divider);
    }
  }
  periods_pulled_ = view.newest;
}

void VerilatedBoardDevice::Exchange(const io::FrameBytes& mosi, io::FrameBytes& miso) noexcept {
  Track(mosi);
  max_late_ps_ = std::max(max_late_ps_, bench_.now_ps() - target_ps_);
  bench_.RunUntil(target_ps_);
  miso.fill(0);
  bench_.Transfer(slot_, mosi, miso, timing_.shape);
  ++transfers_;
  const bool noop = mosi[0] == static_cast<std::uint8_t>(io::Opcode::kNoop);
  const std::int64_t gap_ns = noop ? timing_.fetch_gap_ns : timing_.request_gap_ns;
  bench_.RunUntil(bench_.now_ps() + gap_ns * 1000);
}

}  // namespace hiltwin::fpga_sim
