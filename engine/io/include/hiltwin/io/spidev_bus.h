#pragma once
/// The real backend: Linux spidev (`/dev/spidevB.C`). An exchange (request + fetch of its
/// answer) is one SPI_IOC_MESSAGE(2): chip select is released between the two 12-byte transfers
/// and the kernel waits kFetchGapNs after the first, so the board has its answer ready.
/// The OS is reached through a small FileOps interface so the set-up and transfer can be tested
/// against a fake without an SPI device (docs/spi-protocol.md: how to verify on a Raspberry Pi).

#include <linux/spi/spidev.h>

#include <array>
#include <cstdint>
#include <string>

#include "hiltwin/io/spi_bus.h"

namespace hiltwin::io {

/// The few system calls spidev needs. The real one forwards to open/ioctl/close.
class FileOps {
 public:
  virtual ~FileOps() = default;
  /// Like open(2): a descriptor, or -1 with `errno_out` set.
  virtual int Open(const char* path, int flags, int& errno_out) noexcept = 0;
  /// Like ioctl(2): the result, or -1 with `errno_out` set.
  virtual int Ioctl(int fd, unsigned long request, void* argument, int& errno_out) noexcept = 0;
  virtual void Close(int fd) noexcept = 0;
};
/// open/ioctl/close of the running system.
FileOps& SystemFileOps() noexcept;

/// SPI settings; defaults are the seed framework's (12-byte frames at 31 MHz, mode 0, 8 bits).
struct SpidevConfig {
  std::uint32_t speed_hz = 31'000'000;
  std::uint8_t mode = 0;  ///< SPI_MODE_0..3 (CPOL/CPHA)
  std::uint8_t bits_per_word = 8;
};

/// The two transfers of one exchange for SPI_IOC_MESSAGE(2): `request` then `fetch`, 12 bytes
/// each at the configured speed and word size; the first releases chip select (cs_change = 1)
/// and is followed by a kFetchGapNs pause (delay_usecs = 2), the second leaves chip select as
/// the controller ends a message. Pure, so the composition is tested without a device.
void ComposeExchangeMessage(const SpidevConfig& config, const FrameBytes& request,
                            FrameBytes& request_miso, const FrameBytes& fetch, FrameBytes& answer,
                            std::array<spi_ioc_transfer, 2>& message) noexcept;

class SpidevBus final : public SpiBus {
 public:
  /// Opens `path`, writes mode, bits per word and speed, reads them back. Throws
  /// std::runtime_error naming the device, the failed step, strerror and what to do.
  SpidevBus(const std::string& path, const SpidevConfig& config, FileOps& ops = SystemFileOps());
  ~SpidevBus() override;
  SpidevBus(const SpidevBus&) = delete;
  SpidevBus& operator=(const SpidevBus&) = delete;

  /// One SPI_IOC_MESSAGE(1) of 12 bytes.
  BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override;
  /// Request and fetch in one SPI_IOC_MESSAGE(2) (ComposeExchangeMessage).
  BusStatus TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                         const FrameBytes& fetch, FrameBytes& answer) noexcept override;
  [[nodiscard]] const char* Name() const noexcept override { return name_.c_str(); }
  [[nodiscard]] const SpidevConfig& config() const noexcept { return config_; }
  /// errno of the last failed transfer (0 if none).
  [[nodiscard]] int last_errno() const noexcept { return last_errno_; }

 private:
  FileOps& ops_;
  SpidevConfig config_;
  std::string name_;
  int fd_ = -1;
  int last_errno_ = 0;
};

}  // namespace hiltwin::io
