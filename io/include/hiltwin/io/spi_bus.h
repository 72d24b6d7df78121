#pragma once
/// The bus under the IcoBoard drivers. Backends implement SpiBus::Transfer (virtual, noexcept);
/// drivers call it only through TimedSpi, a non-virtual wrapper that times every transfer and
/// returns a small status struct (ros2_control's trigger_read pattern), so driver code is the
/// same on every backend.

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
  /// Sends `mosi` and fills `miso` with what the board shifted out during the same transfer.
  virtual BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept = 0;
  /// Backend name for messages ("mock", "wire:lab1", "spidev:/dev/spidev0.0").
  [[nodiscard]] virtual const char* Name() const noexcept = 0;
};

/// A transfer's status plus its timing.
struct TransferStatus {
  BusResult result = BusResult::kOk;
  const char* reason = "";
  kernel_glue::TimeNs start_ns = 0;     ///< clock reading before the transfer
  kernel_glue::TimeNs duration_ns = 0;  ///< how long the backend took
};

/// Running timing statistics of a bus (constant memory, updated on the loop's thread).
struct TransferTiming {
  std::uint64_t transfers = 0;
  kernel_glue::TimeNs total_ns = 0;
  kernel_glue::TimeNs max_ns = 0;
};

/// Non-virtual wrapper: times each transfer with `clock` (the monotonic clock when null).
class TimedSpi {
 public:
  explicit TimedSpi(SpiBus& bus, const kernel_glue::Clock* clock = nullptr) noexcept;
  TimedSpi(const TimedSpi&) = delete;  // may point at its own monotonic clock
  TimedSpi& operator=(const TimedSpi&) = delete;
  TransferStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept;
  [[nodiscard]] const TransferTiming& timing() const noexcept { return timing_; }
  [[nodiscard]] SpiBus& bus() noexcept { return bus_; }
  [[nodiscard]] const SpiBus& bus() const noexcept { return bus_; }

 private:
  SpiBus& bus_;
  const kernel_glue::Clock* clock_;
  kernel_glue::MonotonicClock monotonic_;
  TransferTiming timing_{};
};

}  // namespace hiltwin::io
