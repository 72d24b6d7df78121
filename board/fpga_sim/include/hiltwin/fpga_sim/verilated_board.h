#pragma once
/// The RTL where io::EmulatedFpga sits: an io::SpiDevice whose every Exchange is one SPI transfer
/// to a verilated board on an RtlBench. Board time follows spec15 §4: without a clock, the k-th
/// ALL after INIT happens at origin + k·step (the origin is the bench's, fixed at the first ALL
/// after INIT, so two boards INITed together share it); with a kernel_glue::Clock, at the
/// clock's reading. Before the transfer the bench runs to that time (never backwards); after
/// it the bench idles for the gap the host leaves (2 µs after a request, so the fetch that
/// follows reads its answer; less after a NOOP fetch). A per-device phase shifts its transfers
/// on the common timeline (two boards wired together must not sample at the same clock).

#include <array>
#include <cstdint>

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_lines.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::fpga_sim {

struct DeviceTiming {
  TransferShape shape{};                   ///< SCLK and the rest of each transfer
  std::int64_t request_gap_ns = 2'000;     ///< idle after a transfer that is not a NOOP (spec15 §1)
  std::int64_t fetch_gap_ns = 500;         ///< idle after a NOOP transfer
  std::int64_t phase_ns = 0;               ///< this board's ALLs at board time + phase
  /// ALL k at k·interval instead of k·step (0: the step from INIT). A twin whose messages come
  /// less often than its INIT step leaves the A/B lines quiet at the end of each interval.
  std::int64_t all_interval_ns = 0;
  /// ECS alone fed by an EncoderLineSource: an edge at source time t reaches the A/B inputs at
  /// origin + t + this many clocks, so that the ALL at board time t_k, acted on a fixed latency
  /// later (the transfer, the synchroniser), counts exactly the edges up to t_k, as the model's
  /// readers do. Calibrated against the model (tests/unit/fpga_sim/ecs_feed_test.cpp).
  std::int64_t line_delay_clocks = 315;  // the middle of the 312 .. 319 that match
};

class VerilatedBoardDevice final : public io::SpiDevice {
 public:
  /// `bench` must hold the board for `image` and outlive the device. `clock`: see the file comment.
  VerilatedBoardDevice(RtlBench& bench, io::Image image, const DeviceTiming& timing = {},
                       const kernel_glue::Clock* clock = nullptr) noexcept;

  void Exchange(const io::FrameBytes& mosi, io::FrameBytes& miso) noexcept override;

  /// Twin board alone: the PWM reader's inputs follow this source's duty, asked at every ALL
  /// (not owned; null = duty 0). The waveform is high for round(|duty|·4096) of every 4096 clocks.
  void SetPwmSource(io::PwmSignalSource* source) noexcept { pwm_source_ = source; }
  /// ECS board alone: its A/B inputs replay the periods of this source (a twin board model's
  /// emulator), pulled at every ALL (not owned; null = held still).
  void SetEncoderSource(io::EncoderLineSource* source) noexcept { encoder_source_ = source; }
  /// A board alone: its digital input pins.
  void SetDigitalInputs(const std::array<bool, io::kChannels>& pins) noexcept;

  [[nodiscard]] io::Image image() const noexcept { return image_; }
  [[nodiscard]] RtlBench& bench() noexcept { return bench_; }
  /// Board time (ns, from the origin) of the latest ALL, as io::EmulatedFpga::time_ns().
  [[nodiscard]] std::int64_t time_ns() const noexcept { return time_ns_; }
  /// ALL frames since INIT.
  [[nodiscard]] std::uint64_t data_frames() const noexcept { return data_frames_; }
  [[nodiscard]] std::int64_t step_ns() const noexcept { return step_ns_; }
  /// Transfers done, and the most any started after the time it was due.
  [[nodiscard]] std::uint64_t transfers() const noexcept { return transfers_; }
  [[nodiscard]] std::int64_t max_late_ns() const noexcept { return max_late_ps_ / 1000; }

 private:
  void Track(const io::FrameBytes& mosi) noexcept;
  void ApplyPwmSource() noexcept;
  void PullEncoderPeriods() noexcept;

  RtlBench& bench_;
  io::Image image_;
  Slot slot_;
  DeviceTiming timing_;
  const kernel_glue::Clock* clock_;
  io::PwmSignalSource* pwm_source_ = nullptr;
  io::EncoderLineSource* encoder_source_ = nullptr;
  std::uint64_t periods_pulled_ = 0;  ///< newest source period queued on the bench
  io::EncoderPeriod period_scratch_{};
  std::array<double, io::kChannels> duty_{};

  bool initialised_ = false;
  bool origin_known_ = false;
  std::int64_t origin_ps_ = 0;
  std::int64_t step_ns_ = 0;
  std::int64_t time_ns_ = 0;
  std::uint64_t data_frames_ = 0;
  std::int64_t target_ps_ = 0;  ///< when this transfer should start
  std::uint64_t transfers_ = 0;
  std::int64_t max_late_ps_ = 0;
};

}  // namespace hiltwin::fpga_sim
