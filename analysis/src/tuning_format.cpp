#include "tuning_format.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace hiltwin::analysis::detail {

std::string Format(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int size = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string out(static_cast<std::size_t>(std::max(size, 0)) + 1, '\0');
  std::vsnprintf(out.data(), out.size(), format, args);
  va_end(args);
  out.resize(static_cast<std::size_t>(std::max(size, 0)));
  return out;
}

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
