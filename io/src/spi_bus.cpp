#include "hiltwin/io/spi_bus.h"

#include "hiltwin/io/peer_link.h"

namespace hiltwin::io {

const char* ToString(BusResult result) noexcept {
  switch (result) {
    case BusResult::kOk: return "ok";
    case BusResult::kIoError: return "I/O error";
    case BusResult::kPeerLost: return "peer lost";
    case BusResult::kPeerAbsent: return "peer absent";
    case BusResult::kPeerStopped: return "peer stopped";
  }
  return "?";
}

const char* ToString(StopCause cause) noexcept {
  switch (cause) {
    case StopCause::kNone: return "none";
    case StopCause::kFinished: return "finished";
    case StopCause::kStopRequested: return "stop_requested";
    case StopCause::kQosAbort: return "qos_abort";
    case StopCause::kFault: return "fault";
    case StopCause::kPeerStopped: return "peer_stopped";
  }
  return "?";
}

TimedSpi::TimedSpi(SpiBus& bus, const kernel_glue::Clock* clock) noexcept
    : bus_(bus), clock_(clock != nullptr ? clock : &monotonic_) {}

TransferStatus TimedSpi::Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept {
  TransferStatus status;
  status.start_ns = clock_->NowNs();
  const BusStatus bus_status = bus_.Transfer(mosi, miso);
  status.duration_ns = clock_->NowNs() - status.start_ns;
  status.result = bus_status.result;
  status.reason = bus_status.reason;
  ++timing_.transfers;
  timing_.total_ns += status.duration_ns;
  if (status.duration_ns > timing_.max_ns) timing_.max_ns = status.duration_ns;
  return status;
}

}  // namespace hiltwin::io
