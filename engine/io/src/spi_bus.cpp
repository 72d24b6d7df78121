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
    case BusResult::kWireCorrupted: return "wire corrupted";
    case BusResult::kPeerMismatch: return "peer on another clock";
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

namespace {
// Never advanced: reads 0 if anything reads it; TimedSpi recognises it by its address.
const kernel_glue::VirtualClock kUntimedClock{0};
}  // namespace

const kernel_glue::Clock* UntimedTransfers() noexcept { return &kUntimedClock; }

TimedSpi::TimedSpi(SpiBus& bus, const kernel_glue::Clock* clock) noexcept
    : bus_(bus),
      clock_(clock != nullptr ? clock : &monotonic_),
      timed_(clock != UntimedTransfers()) {}

BusStatus SpiBus::TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                                const FrameBytes& fetch, FrameBytes& answer) noexcept {
  const BusStatus first = Transfer(request, request_miso);
  if (first.result == BusResult::kIoError) return first;
  return Transfer(fetch, answer);
}

TransferStatus TimedSpi::Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept {
  const kernel_glue::TimeNs start_ns = timed_ ? clock_->NowNs() : 0;
  return Record(start_ns, bus_.Transfer(mosi, miso));
}

TransferStatus TimedSpi::TimedTransferPair(const FrameBytes& request, FrameBytes& request_miso,
                                           const FrameBytes& fetch, FrameBytes& answer) noexcept {
  const kernel_glue::TimeNs start_ns = clock_->NowNs();
  return Record(start_ns, bus_.TransferPair(request, request_miso, fetch, answer));
}

TransferStatus TimedSpi::Record(kernel_glue::TimeNs start_ns, const BusStatus& bus_status) noexcept {
  TransferStatus status;
  status.start_ns = start_ns;
  status.duration_ns = timed_ ? clock_->NowNs() - start_ns : 0;
  status.result = bus_status.result;
  status.reason = bus_status.reason;
  ++timing_.transfers;
  timing_.total_ns += status.duration_ns;
  if (status.duration_ns > timing_.max_ns) timing_.max_ns = status.duration_ns;
  return status;
}

}  // namespace hiltwin::io
