#pragma once
// liblttng-ctl's return codes as text (liblttng-ctl builds only).

#include <lttng/lttng.h>

#include <string>

namespace hiltwin::trace_capture {

/// "Session name already exists (code -54)" for a liblttng-ctl code. Calls return negative
/// codes, the *_ext calls a positive enum lttng_error_code; lttng_strerror wants the former.
inline std::string LttngText(int code) {
  const int negative = code > 0 ? -code : code;
  return std::string(lttng_strerror(negative)) + " (code " + std::to_string(negative) + ")";
}

}  // namespace hiltwin::trace_capture
