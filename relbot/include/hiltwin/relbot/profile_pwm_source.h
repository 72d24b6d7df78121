#pragma once
/// An input profile played into the emulated board's PWM reader, as a controller would play it:
/// what drives the mock board's twin when no controller is connected.

#include <array>
#include <cmath>
#include <cstdint>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/relbot/input_profile.h"

namespace hiltwin::app {

/// Plays an input profile into the emulated board's PWM reader the way a controller would:
/// sampled and held at the controller's rate (thesis fig. 5.1 was played by a 1 kHz ECS).
/// The mock board's time is its frame count times the twin's whole-nanosecond period, so the
/// source counts in frames: frame k holds the controller's sample floor(k * controller rate /
/// twin rate), taken at that sample's exact time. A frame that coincides with a controller
/// sample therefore reads it whatever the period's rounding (7 kHz is 142857 ns, and 7 of them
/// end 1 ns before the millisecond: counted in nanoseconds, every such frame would read the
/// previous sample, a whole period of extra delay at some rates and none at others).
class ProfilePwmSource final : public io::PwmSignalSource {
 public:
  ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                   double twin_rate_hz) noexcept;
  void DutyAt(std::int64_t t_ns, std::array<double, io::kChannels>& duty_out) noexcept override {
    // Frame after frame the controller's sample holds (4 frames of a 1 kHz controller into a
    // 4 kHz twin): a time within the range the held sample is known to cover plays it again.
    if (t_ns >= held_from_ns_ && t_ns < held_until_ns_) [[likely]] {
      duty_out = held_;
      return;
    }
    Resample(t_ns);
    duty_out = held_;
  }

 private:
  const InputProfile& profile_;
  double controller_rate_hz_;
  double twin_rate_hz_;
  /// Frame index of t_ns on the twin's grid (0 before it starts): round(t_ns / period).
  [[nodiscard]] double FrameOf(std::int64_t t_ns) const noexcept;
  /// Frame `frame` in controller samples; its floor is the frame's sample (the contract's
  /// expression).
  [[nodiscard]] double FrameRatio(double frame) const noexcept {
    return frame * controller_rate_hz_ / twin_rate_hz_;
  }
  [[nodiscard]] double SampleOf(double frame) const noexcept {
    return std::floor(FrameRatio(frame));
  }
  /// Looks up the sample of t_ns and the range of times that read it.
  void Resample(std::int64_t t_ns) noexcept;
  /// Ends the held range at the first time whose frame reads a sample after `sample` (at most
  /// 2^51 ns, where frames leave integers; empty when that cannot be told), and notes that
  /// frame's end and sample.
  void HoldUntilNextSample(double sample, std::int64_t t_ns) noexcept;

  std::int64_t period_ns_;  ///< whole nanoseconds, as the board counts them
  double twin_period_ns_;   ///< the same, as a double
  // The controller holds a sample over several frames (4 at 1 kHz into a 4 kHz twin): the
  // last sample's duty is kept rather than looked up again, and the lookup starts where the
  // last one ended.
  double last_sample_;  ///< NaN until the first lookup
  Duty last_duty_;
  std::size_t cursor_ = 0;
  // The sample is a non-decreasing function of time (frames and their samples both are): every
  // time in [held_from_ns_, held_until_ns_) reads the sample held_ was played from. Empty
  // until the first lookup.
  std::int64_t held_from_ns_ = 0;
  std::int64_t held_until_ns_ = 0;
  std::array<double, io::kChannels> held_{};
  // The frame [held_until_ns_, next_frame_end_ns_) reads next_sample_ (empty: not known).
  std::int64_t next_frame_end_ns_ = 0;
  double next_sample_ = 0.0;
  bool ranges_;                ///< the rates make a sample grid (positive and finite)
  double frames_per_sample_;   ///< an estimate only: the exact test settles every boundary
  double last_frame_;          ///< the last frame below 2^51 ns
};

}  // namespace hiltwin::app
