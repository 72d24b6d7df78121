#pragma once
/// The bus under the IcoBoard drivers. Backends implement SpiBus::Transfer (virtual, noexcept)
/// and may override TransferPair (a request transfer and the fetch of its answer in one bus
/// transaction); drivers call them only through TimedSpi, a non-virtual wrapper that times every
/// exchange and returns a small status struct (ros2_control's trigger_read pattern), so driver
/// code is the same on every backend.

#include <cstdint>

#include "hiltwin/io/frame.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::io {

/// Outcome of one transfer at bus level (the frame's content is judged by the driver).
enum class BusResult : std::uint8_t {
  kOk,
  kIoError,     ///< the transfer itself failed (ioctl error, short transfer)
  kPeerLost,    ///< wire: the other process stopped updating its heartbeat
  kPeerAbsent,  ///< wire: no peer has attached yet (the local board still answered)
  kPeerStopped, ///< wire: the peer announced the end of its run (the local board still answered)
  /// wire: the shared segment held a value no hiltwin process writes (another process writes
  /// into it); nothing more is read from it. An I/O fault, but the local board still answered.
  kWireCorrupted,
  /// wire: the peer runs on the other clock (one side --clock realtime, the other virtual);
  /// refused, as an I/O fault, before anything is read from it.
  kPeerMismatch,
};
[[nodiscard]] const char* ToString(BusResult result) noexcept;

/// What a backend returns: a result and, when not kOk, a static message saying why.
struct BusStatus {
  BusResult result = BusResult::kOk;
  const char* reason = "";  ///< static storage: safe to keep, never allocated
};

/// One full-duplex SPI transfer of a 12-byte frame. Implementations never throw or allocate.
class SpiBus {
 public:
  virtual ~SpiBus() = default;
  /// Sends `mosi` and fills `miso` with what the board shifted out during the same transfer
  /// (from a pipelined board: the answer to the previous request).
  virtual BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept = 0;
  /// Two transfers with chip select released between them and at least kFetchGapNs from the
  /// end of the first to the start of the second (docs/spi-protocol.md, "Pipelined answers"):
  /// `request` (its MISO into `request_miso`), then `fetch` (its MISO, the board's answer to
  /// `request`, into `answer`). The default calls Transfer twice (an emulated board answers at
  /// once, so the gap is moot) and stops after a first transfer that failed with kIoError;
  /// otherwise the second transfer's status is returned.
  virtual BusStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                                 const FrameBytes& fetch, FrameBytes& answer) noexcept;
  /// Backend name for messages ("mock", "wire:lab1", "spidev:/dev/spidev0.0").
  [[nodiscard]] virtual const char* Name() const noexcept = 0;
};

/// Least time between the end of a request transfer and the start of its fetch: the gateware
/// has the answer ready 1.5 µs after the request's last SCLK edge (spec: 150 clocks at 100 MHz).
constexpr std::int64_t kFetchGapNs = 2'000;

/// A transfer's status plus its timing.
struct TransferStatus {
  BusResult result = BusResult::kOk;
  const char* reason = "";
  kernel_glue::TimeNs start_ns = 0;     ///< clock reading before the transfer
  kernel_glue::TimeNs duration_ns = 0;  ///< how long the backend took
};

/// Running timing statistics of a bus (constant memory, updated on the loop's thread).
struct TransferTiming {
  std::uint64_t transfers = 0;  ///< single transfers plus request/fetch pairs (one per exchange)
  kernel_glue::TimeNs total_ns = 0;
  kernel_glue::TimeNs max_ns = 0;
};

/// TimedSpi's clock for a driver whose transfer times nobody reads (the twin's loop: the
/// executive times its whole I/O step): no clock is read, transfers are counted with duration 0.
[[nodiscard]] const kernel_glue::Clock* UntimedTransfers() noexcept;

/// Non-virtual wrapper: times each transfer with `clock` (the monotonic clock when null; none
/// for UntimedTransfers()).
class TimedSpi {
 public:
  explicit TimedSpi(SpiBus& bus, const kernel_glue::Clock* clock = nullptr) noexcept;
  TimedSpi(const TimedSpi&) = delete;  // may point at its own monotonic clock
  TimedSpi& operator=(const TimedSpi&) = delete;
  TransferStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept;
  /// SpiBus::TransferPair, timed and counted as one transfer (an exchange).
  TransferStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                              const FrameBytes& fetch, FrameBytes& answer) noexcept {
    if (timed_) return TimedTransferPair(request, request_miso, fetch, answer);
    // Untimed, inline (the twin's exchange on every cycle): what Record adds for a duration of
    // 0 is the count alone.
    const BusStatus bus_status = bus_.TransferPair(request, request_miso, fetch, answer);
    ++timing_.transfers;
    TransferStatus status;
    status.result = bus_status.result;
    status.reason = bus_status.reason;
    return status;
  }
  [[nodiscard]] const TransferTiming& timing() const noexcept { return timing_; }
  [[nodiscard]] SpiBus& bus() noexcept { return bus_; }
  [[nodiscard]] const SpiBus& bus() const noexcept { return bus_; }

 private:
  SpiBus& bus_;
  const kernel_glue::Clock* clock_;
  bool timed_;  ///< false for UntimedTransfers(): two clock reads per exchange saved
  kernel_glue::MonotonicClock monotonic_;
  TransferStatus TimedTransferPair(const FrameBytes& request, FrameBytes& request_miso,
                                   const FrameBytes& fetch, FrameBytes& answer) noexcept;
  /// Adds one transfer (or pair) that began at `start_ns` to the timing statistics.
  TransferStatus Record(kernel_glue::TimeNs start_ns, const BusStatus& bus_status) noexcept;

  TransferTiming timing_{};
};

}  // namespace hiltwin::io
