#pragma once
// Private to the analysis module: how every `hiltwin tune` output (the reason sentence, the
// text report, the HTML page) writes a rate, a duration and an error, so they say a figure
// the same way.

#include <cstdint>
#include <string>

#include "hiltwin/report_kit/string_format.h"

namespace hiltwin::analysis::detail {

/// "8333 Hz": whole hertz, floored like the recommendation, so a bound never reads higher
/// than the rate it allows.
[[nodiscard]] std::string HzText(double rate_hz);

/// "35.0 us" from nanoseconds; below 10 us with three decimals ("0.118 us").
[[nodiscard]] std::string UsText(double ns);

/// "0.100 mm" from metres.
[[nodiscard]] std::string MmText(double metres);

}  // namespace hiltwin::analysis::detail
