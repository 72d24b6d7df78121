#pragma once
/// Why a recording cannot be made here (no session daemon and no right to start one, no
/// access to tracefs, ...): what() says what was refused and what to do. `hiltwin trace` exits
/// 5 with it (an environment fault, not bad input).

#include <stdexcept>

namespace hiltwin::trace_capture {

class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hiltwin::trace_capture
