#pragma once
/// The real backend: Linux spidev (`/dev/spidevB.C`), one SPI_IOC_MESSAGE(1) per 12-byte frame.
/// The OS is reached through a small FileOps interface so the set-up and transfer can be tested
/// against a fake without an SPI device (docs/spi-protocol.md: how to verify on a Raspberry Pi).

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

class SpidevBus final : public SpiBus {
 public:
  /// Opens `path`, writes mode, bits per word and speed, reads them back. Throws
  /// std::runtime_error naming the device, the failed step, strerror and what to do.
  SpidevBus(const std::string& path, const SpidevConfig& config, FileOps& ops = SystemFileOps());
  ~SpidevBus() override;
  SpidevBus(const SpidevBus&) = delete;
  SpidevBus& operator=(const SpidevBus&) = delete;

  BusStatus Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept override;
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
