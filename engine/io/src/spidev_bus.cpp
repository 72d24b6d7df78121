#include "hiltwin/io/spidev_bus.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace hiltwin::io {
namespace {

class SystemOps final : public FileOps {
 public:
  int Open(const char* path, int flags, int& errno_out) noexcept override {
    const int fd = ::open(path, flags);
    errno_out = fd < 0 ? errno : 0;
    return fd;
  }
  int Ioctl(int fd, unsigned long request, void* argument, int& errno_out) noexcept override {
    const int result = ::ioctl(fd, request, argument);
    errno_out = result < 0 ? errno : 0;
    return result;
  }
  void Close(int fd) noexcept override { ::close(fd); }
};

}  // namespace

FileOps& SystemFileOps() noexcept {
  static SystemOps ops;
  return ops;
}

SpidevBus::SpidevBus(const std::string& path, const SpidevConfig& config, FileOps& ops)
    : ops_(ops), config_(config), name_("spidev:" + path) {
  int error = 0;
  fd_ = ops_.Open(path.c_str(), O_RDWR | O_CLOEXEC, error);
  if (fd_ < 0) {
    throw std::runtime_error(
        "cannot open " + path + ": " + std::strerror(error) +
        "; enable SPI (Raspberry Pi OS: dtparam=spi=on in /boot/firmware/config.txt, then "
        "reboot), check that the device exists (ls /dev/spidev*) and that you may use it "
        "(group spi)");
  }
  auto set = [&](unsigned long request, void* value, const char* what) {
    int err = 0;
    if (ops_.Ioctl(fd_, request, value, err) < 0) {
      ops_.Close(fd_);
      fd_ = -1;
      throw std::runtime_error(std::string("cannot ") + what + " on " + path + ": " +
                               std::strerror(err) + "; check that the device is an spidev node");
    }
  };
  std::uint8_t mode = config_.mode;
  std::uint8_t bits = config_.bits_per_word;
  std::uint32_t speed = config_.speed_hz;
  set(SPI_IOC_WR_MODE, &mode, "set SPI mode");
  set(SPI_IOC_WR_BITS_PER_WORD, &bits, "set bits per word");
  set(SPI_IOC_WR_MAX_SPEED_HZ, &speed, "set SPI speed");
  // Read back: a driver may round the speed down; keep what is really in effect.
  set(SPI_IOC_RD_MODE, &mode, "read back SPI mode");
  set(SPI_IOC_RD_BITS_PER_WORD, &bits, "read back bits per word");
  set(SPI_IOC_RD_MAX_SPEED_HZ, &speed, "read back SPI speed");
  if (mode != config_.mode || bits != config_.bits_per_word) {
    ops_.Close(fd_);
    fd_ = -1;
    throw std::runtime_error("SPI device " + path + " did not accept mode " +
                             std::to_string(config_.mode) + " with " +
                             std::to_string(config_.bits_per_word) + " bits per word");
  }
  config_.speed_hz = speed;
}

SpidevBus::~SpidevBus() {
  if (fd_ >= 0) ops_.Close(fd_);
}

namespace {

void FillTransfer(const SpidevConfig& config, const FrameBytes& mosi, FrameBytes& miso,
                  spi_ioc_transfer& transfer) noexcept {
  std::memset(&transfer, 0, sizeof transfer);
  // The kernel ABI carries user pointers as 64-bit integers.
  transfer.tx_buf = reinterpret_cast<std::uintptr_t>(mosi.data());
  transfer.rx_buf = reinterpret_cast<std::uintptr_t>(miso.data());
  transfer.len = static_cast<std::uint32_t>(kFrameBytes);
  transfer.speed_hz = config.speed_hz;
  transfer.bits_per_word = config.bits_per_word;
  transfer.delay_usecs = 0;
  transfer.cs_change = 0;
}

}  // namespace

void ComposeExchangeMessage(const SpidevConfig& config, const FrameBytes& request,
                            FrameBytes& request_miso, const FrameBytes& fetch, FrameBytes& answer,
                            std::array<spi_ioc_transfer, 2>& message) noexcept {
  FillTransfer(config, request, request_miso, message[0]);
  FillTransfer(config, fetch, answer, message[1]);
  // Release CS after the request (the board acts on it while CS is high) and keep it released
  // for the fetch gap; the last transfer of a message ends with CS released anyway.
  message[0].cs_change = 1;
  message[0].delay_usecs = static_cast<std::uint16_t>((kFetchGapNs + 999) / 1000);
}

BusStatus SpidevBus::Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept {
  spi_ioc_transfer transfer{};
  FillTransfer(config_, mosi, miso, transfer);
  int error = 0;
  const int result = ops_.Ioctl(fd_, SPI_IOC_MESSAGE(1), &transfer, error);
  if (result < 0) {
    last_errno_ = error;
    return {BusResult::kIoError, "spidev transfer failed (ioctl SPI_IOC_MESSAGE)"};
  }
  if (result != static_cast<int>(kFrameBytes)) {
    return {BusResult::kIoError, "spidev transferred fewer than 12 bytes"};
  }
  return {};
}

BusStatus SpidevBus::TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                                  const FrameBytes& fetch, FrameBytes& answer) noexcept {
  std::array<spi_ioc_transfer, 2> message{};
  ComposeExchangeMessage(config_, request, request_miso, fetch, answer, message);
  int error = 0;
  const int result = ops_.Ioctl(fd_, SPI_IOC_MESSAGE(2), message.data(), error);
  if (result < 0) {
    last_errno_ = error;
    return {BusResult::kIoError, "spidev transfer failed (ioctl SPI_IOC_MESSAGE)"};
  }
  if (result != static_cast<int>(2 * kFrameBytes)) {
    return {BusResult::kIoError, "spidev transferred fewer than 24 bytes (request and fetch)"};
  }
  return {};
}

}  // namespace hiltwin::io
