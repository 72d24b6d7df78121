#pragma once
/// What one per-cycle board exchange came to: the vocabulary every run task, the run assembly
/// and the reports share, apart from the IcoBoard drivers that produce it (icoboard.h), so a
/// user of the status does not include the drivers.

#include <cstdint>

namespace hiltwin::io {

/// Outcome of one per-cycle exchange. On anything but kOk the caller's inputs were left as they
/// were (previous values held) and `reason` (static storage) says why.
struct ExchangeStatus {
  enum class Code : std::uint8_t {
    kOk,
    kCorrupted,  ///< answer failed its checks, or the board rejected our request
    kMissed,     ///< no answer, or a stale one (sequence mismatch)
    kFault,      ///< the link is down: bus error, wire peer lost, board lost its INIT
  };
  Code code = Code::kOk;
  const char* reason = "";
  std::int64_t transfer_ns = 0;  ///< time the bus took
  bool pulse_limit = false;      ///< an encoder change exceeded what one period can emit
  bool peer_absent = false;      ///< wire: no peer attached yet (values are idle)
  /// The board took the request and answered it correctly: always with kOk, and also with the
  /// kFault of a lost wire peer (this side's own board still answered).
  bool board_answered = false;
  /// wire: the peer announced the end of its run; why (static text). Null while it runs.
  const char* peer_stopped = nullptr;
  [[nodiscard]] bool ok() const noexcept { return code == Code::kOk; }
};
[[nodiscard]] const char* ToString(ExchangeStatus::Code code) noexcept;

}  // namespace hiltwin::io
