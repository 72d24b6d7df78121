#pragma once
/// A link with a process on its other end (the wire backend): the run assembly waits in `ready`
/// until that process is there, and tells it why this side stopped, so that either side may
/// start first and a stop on one side ends the other cleanly (not as a broken link). A real
/// SPI board and the in-process mock have no such process; their backends offer no PeerLink.

#include <cstdint>

#include "hiltwin/io/spi_bus.h"

namespace hiltwin::io {

/// Why a process on a link stopped, as the other side learns it.
enum class StopCause : std::uint8_t {
  kNone,           ///< still running (or never announced)
  kFinished,       ///< it ran its planned duration
  kStopRequested,  ///< a signal or a stop command
  kQosAbort,       ///< its QoS policy aborted the run
  kFault,          ///< an I/O or model fault
  kPeerStopped,    ///< it stopped because its own peer (this side) had stopped
};
/// "finished", "stop_requested", ... (the run report's stop_reason words).
[[nodiscard]] const char* ToString(StopCause cause) noexcept;

class PeerLink {
 public:
  virtual ~PeerLink() = default;
  /// Start-up, while waiting: keeps this side's presence fresh without a transfer and returns
  /// the peer's status now (kOk: attached, alive and not stopped). Never blocks.
  [[nodiscard]] virtual BusStatus Poll() noexcept = 0;
  /// After the last transfer: tells the peer that this side has stopped, and why. The peer's
  /// next transfer returns kPeerStopped with a message naming the cause.
  virtual void AnnounceStop(StopCause cause) noexcept = 0;
  /// While the loop runs, from the control thread (every 100 ms): tells the peer this process
  /// is alive even while its loop is busy between two transfers without a deadline, e.g. a
  /// lockstep loop waiting for its log writer. Only atomics; safe beside the loop's transfers.
  virtual void KeepAlive() noexcept {}
};

}  // namespace hiltwin::io
