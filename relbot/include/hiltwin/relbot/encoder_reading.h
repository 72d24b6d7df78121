#pragma once
/// Whether a controller can follow the encoders at the rate it reads them (issue 34: a 10 Hz ECS
/// against a 4 kHz twin decoded 0 edges and still passed). Two limits, both in
/// docs/spi-protocol.md ("Encoder emulator semantics"):
///
/// - the count the controller reads is 14 bits (16384 counts) and unwrapped from one read to
///   the next, so a wheel may move at most 8191 counts between two reads: more is taken for
///   the opposite way round;
/// - the emulated encoder lines (`--io wire`) keep the edges of the last kEncoderLineHistory
///   (128) twin periods; a controller that reads less often finds them overwritten, and its
///   counts jump without being decoded (counted as resyncs).
///
/// Pure: the commands call it before the run, print its lines on stderr and put them in the
/// report's `warnings`.

#include <optional>
#include <string>
#include <vector>

#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {

struct EncoderReading {
  double controller_rate_hz = 1000.0;  ///< how often the controller reads the counts
  /// The twin's rate when its emulated lines feed the controller's readers (a wire); none for a
  /// real board, whose readers count every edge however rarely they are read.
  std::optional<double> twin_rate_hz;
  /// The fastest a wheel's count changes, counts/s; none when not known (a plant of unknown
  /// speed): then only the lines' history is checked.
  std::optional<double> top_counts_per_s;
  std::string rate_flag = "--rate";  ///< the flag that sets the controller's rate, for the fix
};

/// The RELbot's top count rate: the motor's no-load speed at full supply (V / k_e rad/s) times
/// the encoder's counts per motor turn over 2 pi.
[[nodiscard]] double TopCountsPerSecond(const RelbotParams& params) noexcept;

/// One line per limit the controller's rate breaks, each with the rate that would keep it;
/// empty when the controller can follow the counts.
[[nodiscard]] std::vector<std::string> EncoderReadingWarnings(const EncoderReading& reading);

}  // namespace hiltwin::app
