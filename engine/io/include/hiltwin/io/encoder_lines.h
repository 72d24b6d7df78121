#pragma once
/// The encoder lines between the twin board's encoder emulator and the ECS board's quadrature
/// readers (thesis §2.2.1, §3.7). The emulator publishes every period it starts to an
/// EncoderLineSink; the ECS board replays the A/B edges of those periods, at their clock-accurate
/// times, into one QuadratureReader per channel (EncoderLineReader). So the counts the ECS reads
/// come from decoding edges spread in time, as on the real boards, and an edge sequence a real
/// reader would miscount shows up in the reader's error counters. Pure logic, noexcept,
/// allocation-free, O(edges) per read.

#include <array>
#include <cstdint>
#include <limits>

#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/frame.h"

namespace hiltwin::io {

/// One emulator period of all channels (they all start at the same sampling moment).
struct EncoderPeriod {
  std::uint64_t index = 0;  ///< 1, 2, ... in the order the periods started; 0 = none
  std::array<PulseSegment, kChannels> channels{};
  [[nodiscard]] std::int64_t start_ns() const noexcept { return channels[0].start_ns; }
};

/// Where a twin board publishes each period its emulator starts (at INIT and every ALL).
class EncoderLineSink {
 public:
  virtual ~EncoderLineSink() = default;
  /// The sink numbers the periods (so a restarted twin continues the numbering on a wire).
  virtual void OnPeriod(const std::array<PulseSegment, kChannels>& channels) noexcept = 0;
};

/// What the lines look like to an ECS board at one read.
struct LineView {
  std::uint64_t newest = 0;  ///< newest period started; 0 = the emulator never ran
  /// Edges up to this time are final. A wire twin in the middle of a sample may still publish a
  /// period that starts (and cancels edges) after this moment but before the reader's time.
  std::int64_t known_until_ns = std::numeric_limits<std::int64_t>::max();
};

/// The lines as an ECS board reads them.
class EncoderLineSource {
 public:
  virtual ~EncoderLineSource() = default;
  /// Called once per ALL frame of the ECS board, at board time `t_ns`.
  virtual LineView Lines(std::int64_t t_ns) noexcept = 0;
  /// Copies period `index` into `out`; false (and `out` unspecified) when it is not, or no
  /// longer, available.
  virtual bool Period(std::uint64_t index, EncoderPeriod& out) noexcept = 0;
};

/// Periods kept for a reader that reads less often than the emulator samples: 128 twin periods
/// (32 ms at 4 kHz) may pass between two ECS reads before edges are lost (then counted as a
/// resync).
constexpr std::uint64_t kEncoderLineHistory = 128;

/// In-process lines: the last kEncoderLineHistory periods in a ring.
class EncoderLineHistory : public EncoderLineSink, public EncoderLineSource {
 public:
  void OnPeriod(const std::array<PulseSegment, kChannels>& channels) noexcept override;
  LineView Lines(std::int64_t t_ns) noexcept override;
  bool Period(std::uint64_t index, EncoderPeriod& out) noexcept override;

 private:
  std::array<EncoderPeriod, kEncoderLineHistory> ring_{};
  std::uint64_t newest_ = 0;
};

/// The ECS reader's view of its input, summed over the channels.
struct EncoderLineCounters {
  std::uint64_t edges = 0;                ///< A/B edges fed to the readers
  std::uint64_t illegal_transitions = 0;  ///< both lines changed at once: a count lost
  std::uint64_t too_fast_edges = 0;       ///< a state held shorter than the synchroniser needs
  /// The lines jumped without edges: periods were overwritten before the reader got to them
  /// (the ECS read less than once per kEncoderLineHistory twin periods) or the twin restarted.
  std::uint64_t resyncs = 0;
};

/// The ECS board's four quadrature readers and the replay of the emulator's edges into them.
class EncoderLineReader {
 public:
  /// INIT / RESET: the next Update loads the position the lines are at (power-up), uncounted.
  void Reset() noexcept { current_.index = 0; }
  /// Feeds every edge emitted up to `t_ns` (board time) to the readers in time order. While
  /// `stuck`, the lines move but the readers see nothing (fault injection: a frozen input).
  void Update(EncoderLineSource& source, std::int64_t t_ns, bool stuck) noexcept;

  /// The 14-bit count the ECS reads for channel c.
  [[nodiscard]] std::int32_t relative_counts(std::size_t c) const noexcept {
    return readers_[c].relative_counts();
  }
  [[nodiscard]] const QuadratureReader& reader(std::size_t c) const noexcept { return readers_[c]; }
  /// The period being replayed (index 0 before the first lines since INIT).
  [[nodiscard]] const EncoderPeriod& period() const noexcept { return current_; }
  [[nodiscard]] EncoderLineCounters counters() const noexcept;

 private:
  void ReplayCurrent(std::int64_t until_ns, bool stuck) noexcept;
  /// Puts the lines where `current_` has them at `t_ns`, without edges (load or resync).
  void JumpTo(std::int64_t t_ns, bool load, bool stuck) noexcept;

  EncoderPeriod current_{};
  EncoderPeriod next_{};
  std::array<std::uint32_t, kChannels> edges_done_{};  ///< edges of current_ already replayed
  std::array<std::int64_t, kChannels> line_pos_{};     ///< the lines' position, unwrapped
  std::array<QuadratureReader, kChannels> readers_{};
  std::uint64_t edges_ = 0;
  std::uint64_t resyncs_ = 0;
};

}  // namespace hiltwin::io
