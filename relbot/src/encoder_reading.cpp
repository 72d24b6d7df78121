#include "hiltwin/relbot/encoder_reading.h"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/encoder_lines.h"

namespace hiltwin::app {
namespace {

/// The most a count may change between two reads and still unwrap the right way round.
constexpr double kMaxCountsPerRead = io::kEncoderResolution / 2 - 1;  // 8191

std::string Hz(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g Hz", value);
  return text;
}

}  // namespace

double TopCountsPerSecond(const RelbotParams& p) noexcept {
  const double motor_rad_per_s = p.supply_voltage_v / p.motor_back_emf_constant_v_s_per_rad;
  return motor_rad_per_s * p.encoder_counts_per_motor_rev / (2.0 * std::numbers::pi);
}

std::vector<std::string> EncoderReadingWarnings(const EncoderReading& r) {
  std::vector<std::string> lines;
  if (!(r.controller_rate_hz > 0.0)) return lines;  // refused by the rate's own check
  const auto history = static_cast<double>(io::kEncoderLineHistory);
  if (r.twin_rate_hz && *r.twin_rate_hz / r.controller_rate_hz > history) {
    const std::string fix =
        "raise " + r.rate_flag + " to at least " + Hz(std::ceil(*r.twin_rate_hz / history));
    lines.push_back(
        "the controller at " + Hz(r.controller_rate_hz) + " reads the encoders every " +
        std::to_string(std::lround(*r.twin_rate_hz / r.controller_rate_hz)) +
        " periods of the twin at " + Hz(*r.twin_rate_hz) + "; the emulated encoder lines keep " +
        std::to_string(io::kEncoderLineHistory) +
        ", so the edges in between are lost and the counts jump undecoded (resyncs): " + fix);
  }
  if (r.top_counts_per_s && *r.top_counts_per_s / r.controller_rate_hz > kMaxCountsPerRead) {
    const std::string fix = "raise " + r.rate_flag + " to at least " +
                            Hz(std::ceil(*r.top_counts_per_s / kMaxCountsPerRead));
    lines.push_back(
        "at its top speed a wheel moves " +
        std::to_string(std::lround(*r.top_counts_per_s / r.controller_rate_hz)) +
        " counts between two reads of the controller at " + Hz(r.controller_rate_hz) +
        "; the 14-bit count wraps, so more than 8191 reads as the other way round: " + fix);
  }
  return lines;
}

}  // namespace hiltwin::app
