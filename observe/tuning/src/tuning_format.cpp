#include "tuning_format.h"

#include <algorithm>
#include <cmath>

namespace hiltwin::analysis::detail {

std::string HzText(double rate_hz) {
  return Format("%.0f Hz", std::isfinite(rate_hz) ? std::floor(rate_hz) : rate_hz);
}

std::string UsText(double ns) {
  // A fast model steps in a fraction of a microsecond: keep three figures there.
  const double us = ns / 1e3;
  return Format(std::fabs(us) < 10.0 && us != 0.0 ? "%.3f us" : "%.1f us", us);
}

std::string MmText(double metres) { return Format("%.3f mm", metres * 1e3); }

}  // namespace hiltwin::analysis::detail
