#pragma once
/// The RTL bench: one or two Verilator-compiled IcoBoard images (fpga/rtl, tops `icoboard` and
/// `icoboard_inverse`) on one picosecond timeline. The 100 MHz clock has its rising edge k at
/// k·10 ns; an SPI transfer drives SCLK (mode 0, default 31.25 MHz), MOSI and CS with their own
/// edges, merged with the clock edges in time order (edges at the same picosecond are applied
/// together, then evaluated once). Two boards can be wired pin to pin (the ECS board's PWM and
/// direction outputs to the twin's PWM reader, the twin's A/B outputs to the ECS's decoders,
/// each board's digital outputs to the other's inputs); a board alone takes its inputs from the
/// bench (a PWM waveform per channel for the twin, A/B levels for the ECS). Output edges can be
/// recorded with their clock index. Not thread-safe; allocation-free except when recording.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "hiltwin/io/frame.h"

namespace hiltwin::fpga_sim {

/// Picoseconds per 100 MHz clock.
constexpr std::int64_t kClockPs = 10'000;
/// The Raspberry Pi's SPI clock at the seed framework's speed: 250 MHz / 8.
constexpr std::int64_t kDefaultSclkHz = 31'250'000;
/// Power-on reset: clocks run before the first transfer (spec15 §3 asks for >= 32).
constexpr std::uint64_t kPowerOnClocks = 64;

/// Which board of the bench.
enum class Slot : std::uint8_t { kTwin = 0, kEcs = 1 };

/// Output signals of a board, for edge recording.
enum class Signal : std::uint8_t { kEncA, kEncB, kPwm, kPwmDir, kPinOut };

/// One recorded change of a board's 4-bit output bus, seen after rising clock edge `clock`.
struct OutputEdge {
  std::uint64_t clock = 0;
  Slot slot = Slot::kTwin;
  Signal signal = Signal::kEncA;
  std::uint8_t value = 0;  ///< the bus after the change (bit c = channel c)
};

/// How one SPI transfer is clocked.
struct TransferShape {
  std::int64_t sclk_hz = kDefaultSclkHz;
  std::uint32_t bits = static_cast<std::uint32_t>(io::kFrameBytes * 8);  ///< fewer: a short transfer
  /// CS falls this many picoseconds after the transfer is asked for (sweeps the SCLK phase
  /// against the 100 MHz clock).
  std::int64_t lead_ps = 0;
};

/// Quadrature line checks on the twin -> ECS wires (what a real reader would miscount).
struct WireCounters {
  std::uint64_t edges = 0;               ///< A/B level changes, all channels
  std::uint64_t illegal_transitions = 0;  ///< A and B changed in the same clock
  std::uint64_t too_fast = 0;            ///< a state held for fewer than 2 clocks
};

class RtlBench {
 public:
  /// `twin`, `ecs`: which boards exist. `wired`: both pin to pin (needs both).
  RtlBench(bool twin, bool ecs, bool wired);
  ~RtlBench();
  RtlBench(const RtlBench&) = delete;
  RtlBench& operator=(const RtlBench&) = delete;

  [[nodiscard]] bool has(Slot slot) const noexcept;
  [[nodiscard]] bool wired() const noexcept { return wired_; }

  /// Current time and rising clock edges done.
  [[nodiscard]] std::int64_t now_ps() const noexcept { return now_ps_; }
  [[nodiscard]] std::uint64_t clocks() const noexcept { return clocks_; }
  /// Runs the clocks until `t_ps` (nothing when it is in the past).
  void RunUntil(std::int64_t t_ps) noexcept;
  void RunClocks(std::uint64_t n) noexcept { RunUntil(now_ps_ + static_cast<std::int64_t>(n) * kClockPs); }
  /// One SPI transfer to board `slot` starting now (+ shape.lead_ps): MOSI shifted out, MISO
  /// sampled on each rising SCLK edge; ends with CS high half an SCLK period after the last
  /// falling edge. Bits beyond `shape.bits` leave `miso` untouched.
  void Transfer(Slot slot, const io::FrameBytes& mosi, io::FrameBytes& miso,
                const TransferShape& shape = {}) noexcept;

  /// Twin alone: the PWM waveform on channel c, high for `high_clocks` of every 4096 clocks,
  /// direction line `negative`.
  void SetPwmInput(std::size_t c, std::uint32_t high_clocks, bool negative) noexcept;
  /// ECS alone: the A/B levels on channel c (held until changed).
  void SetEncoderInput(std::size_t c, bool a, bool b) noexcept;
  /// ECS alone: plays one emulator period on channel c's A/B inputs, edge j of `pulses` at clock
  /// start_clock + ceil(j·S/N)·D, from position `start_counts` (its levels are taken at
  /// start_clock; edges of the previous period not yet played are dropped, as the emulator
  /// re-plans from where it is). Periods must be queued in start order; up to 8 wait per channel.
  void QueueEncoderPeriod(std::size_t c, std::uint64_t start_clock, std::int32_t start_counts,
                          std::uint32_t pulses, std::int32_t direction, std::uint32_t subticks,
                          std::uint32_t divider) noexcept;
  /// A board alone: its digital input pins (bit c = channel c).
  void SetPinInputs(Slot slot, std::uint8_t pins) noexcept;

  /// Output buses of a board (bit c = channel c).
  [[nodiscard]] std::uint8_t Output(Slot slot, Signal signal) const noexcept;

  /// Records every change of every board's outputs from now on (allocates).
  void StartRecording() { recording_ = true; }
  void StopRecording() noexcept { recording_ = false; }
  [[nodiscard]] const std::vector<OutputEdge>& edges() const noexcept { return edges_; }
  void ClearEdges() noexcept { edges_.clear(); }

  /// The bench-wide origin of board time (ALL 0 after INIT): fixed to the next whole clock the
  /// first time it is asked after ResetOrigin(), so boards INITed together share it.
  std::int64_t Origin() noexcept;
  void ResetOrigin() noexcept { origin_set_ = false; }

  [[nodiscard]] const WireCounters& wire_counters() const noexcept { return wire_; }

 private:
  struct Board;
  struct Edge {
    std::int64_t t_ps;
    bool sclk;
    bool mosi;
    bool cs_n;
    bool sample;  ///< the host samples MISO at this (rising) edge
  };
  void ClockEdge(bool rising) noexcept;
  void AfterRisingEdge() noexcept;
  void ApplyLoneInputs() noexcept;
  void CheckWires(std::uint8_t a, std::uint8_t b) noexcept;
  void Record(Slot slot);
  void ServiceLineFeed() noexcept;
  void SetLevels(std::size_t c, std::int64_t position) noexcept;

  std::unique_ptr<Board> twin_;
  std::unique_ptr<Board> ecs_;
  bool wired_;
  std::int64_t now_ps_ = 0;
  std::uint64_t clocks_ = 0;
  bool clk_high_ = false;
  std::int64_t origin_ps_ = 0;
  bool origin_set_ = false;
  // Lone-board inputs.
  std::array<std::uint32_t, io::kChannels> pwm_high_clocks_{};
  std::uint8_t pwm_dir_in_ = 0;
  bool pwm_active_ = false;
  std::uint32_t pwm_phase_ = 0;
  // ECS alone: A/B periods to play.
  struct FeedPeriod {
    std::uint64_t start_clock = 0;
    std::int64_t start_counts = 0;
    std::uint32_t pulses = 0;
    std::int32_t direction = 0;
    std::uint32_t subticks = 1;
    std::uint32_t divider = 4;
  };
  static constexpr std::size_t kFeedQueue = 8;
  struct Feed {
    FeedPeriod current{};
    std::uint32_t edges_done = 0;
    bool active = false;
    std::array<FeedPeriod, kFeedQueue> queue{};
    std::size_t head = 0;
    std::size_t count = 0;
  };
  std::array<Feed, io::kChannels> feeds_{};
  std::uint64_t feed_next_clock_ = UINT64_MAX;
  // Recording and wire checks.
  bool recording_ = false;
  std::vector<OutputEdge> edges_;
  std::array<std::array<std::uint8_t, 5>, 2> last_out_{};
  WireCounters wire_{};
  std::uint8_t wire_a_ = 0;
  std::uint8_t wire_b_ = 0;
  std::array<std::uint64_t, io::kChannels> wire_changed_at_{};
};

}  // namespace hiltwin::fpga_sim
