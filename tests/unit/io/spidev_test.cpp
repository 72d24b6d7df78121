// spidev set-up and transfer against a fake file layer (no SPI device exists here).
#include "hiltwin/io/spidev_bus.h"

#include <fcntl.h>
#include <linux/spi/spidev.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"

namespace hiltwin::io {
namespace {

/// Records every call; SPI_IOC_MESSAGE(1) and (2) forward their frames to an emulated board in
/// order, so a driver can run over it end to end.
class FakeSpidev final : public FileOps {
 public:
  int Open(const char* path, int flags, int& errno_out) noexcept override {
    opened_path = path;
    open_flags = flags;
    if (fail_open != 0) {
      errno_out = fail_open;
      return -1;
    }
    return 42;
  }
  int Ioctl(int fd, unsigned long request, void* argument, int& errno_out) noexcept override {
    requests.push_back(request);
    if (fd != 42) {
      errno_out = EBADF;
      return -1;
    }
    if (fail_request == request) {
      errno_out = fail_errno;
      return -1;
    }
    switch (request) {
      case SPI_IOC_WR_MODE: mode = *static_cast<std::uint8_t*>(argument); return 0;
      case SPI_IOC_RD_MODE: *static_cast<std::uint8_t*>(argument) = mode; return 0;
      case SPI_IOC_WR_BITS_PER_WORD: bits = *static_cast<std::uint8_t*>(argument); return 0;
      case SPI_IOC_RD_BITS_PER_WORD: *static_cast<std::uint8_t*>(argument) = bits; return 0;
      case SPI_IOC_WR_MAX_SPEED_HZ: speed = *static_cast<std::uint32_t*>(argument); return 0;
      case SPI_IOC_RD_MAX_SPEED_HZ:
        *static_cast<std::uint32_t*>(argument) = speed_cap != 0 && speed > speed_cap ? speed_cap : speed;
        return 0;
      default: break;
    }
    if (request == SPI_IOC_MESSAGE(1) || request == SPI_IOC_MESSAGE(2)) {
      const std::size_t count = request == SPI_IOC_MESSAGE(1) ? 1 : 2;
      const auto* transfers = static_cast<const spi_ioc_transfer*>(argument);
      message.assign(transfers, transfers + count);
      last = transfers[count - 1];
      int bytes = 0;
      for (const spi_ioc_transfer& t : message) {
        FrameBytes tx;
        std::memcpy(tx.data(), reinterpret_cast<const void*>(static_cast<std::uintptr_t>(t.tx_buf)), tx.size());
        FrameBytes rx;
        board.Exchange(tx, rx);
        std::memcpy(reinterpret_cast<void*>(static_cast<std::uintptr_t>(t.rx_buf)), rx.data(), rx.size());
        bytes += static_cast<int>(t.len);
      }
      return short_transfer ? bytes - 6 : bytes;
    }
    errno_out = ENOTTY;
    return -1;
  }
  void Close(int fd) noexcept override { closed.push_back(fd); }

  std::string opened_path;
  int open_flags = 0;
  int fail_open = 0;
  unsigned long fail_request = 0;
  int fail_errno = 0;
  bool short_transfer = false;
  std::uint32_t speed_cap = 0;
  std::uint8_t mode = 0xFF;
  std::uint8_t bits = 0;
  std::uint32_t speed = 0;
  std::vector<unsigned long> requests;
  std::vector<int> closed;
  spi_ioc_transfer last{};              ///< the last transfer of the latest message
  std::vector<spi_ioc_transfer> message;  ///< the latest message's transfers
  EmulatedFpga board{Image::kIcoboardInverse};
};

TEST(SpidevBus, ConfiguresModeBitsAndSpeedAndReadsThemBack) {
  FakeSpidev fake;
  fake.speed_cap = 25'000'000;  // the controller rounds 31 MHz down
  {
    SpidevBus bus("/dev/spidev0.1", SpidevConfig{}, fake);
    EXPECT_EQ(fake.opened_path, "/dev/spidev0.1");
    EXPECT_EQ(fake.open_flags & O_ACCMODE, O_RDWR);
    const std::vector<unsigned long> expected = {SPI_IOC_WR_MODE, SPI_IOC_WR_BITS_PER_WORD,
                                                 SPI_IOC_WR_MAX_SPEED_HZ, SPI_IOC_RD_MODE,
                                                 SPI_IOC_RD_BITS_PER_WORD, SPI_IOC_RD_MAX_SPEED_HZ};
    EXPECT_EQ(fake.requests, expected);
    EXPECT_EQ(fake.mode, 0);
    EXPECT_EQ(fake.bits, 8);
    EXPECT_EQ(fake.speed, 31'000'000U);  // the seed framework's speed was asked for
    EXPECT_EQ(bus.config().speed_hz, 25'000'000U);  // what is really in effect
    EXPECT_STREQ(bus.Name(), "spidev:/dev/spidev0.1");
  }
  EXPECT_EQ(fake.closed, std::vector<int>{42});
}

TEST(SpidevBus, ExchangeIsOneMessageOfRequestAndFetch) {
  FakeSpidev fake;
  SpidevBus bus("/dev/spidev0.0", SpidevConfig{}, fake);
  IcoBoardInverse driver(bus);
  ASSERT_TRUE(driver.Init(250'000).ok);  // the driver runs unchanged over spidev
  ASSERT_EQ(fake.message.size(), 2U);
  EXPECT_EQ(fake.requests.back(), SPI_IOC_MESSAGE(2));
  for (const spi_ioc_transfer& t : fake.message) {
    EXPECT_EQ(t.len, 12U);
    EXPECT_EQ(t.speed_hz, 31'000'000U);
    EXPECT_EQ(t.bits_per_word, 8);
  }
  EXPECT_EQ(fake.message[0].cs_change, 1);  // CS released between request and fetch ...
  EXPECT_EQ(fake.message[0].delay_usecs, 2);  // ... for at least 2 µs
  EXPECT_EQ(fake.message[1].cs_change, 0);
  TwinInputs in;
  ASSERT_TRUE(driver.Exchange({1, 2, 3, 4}, in).ok());
  EXPECT_EQ(fake.board.encoder(3).PositionAt(1'000'000'000), 4);
  EXPECT_EQ(driver.timing().transfers, 2U);  // one per exchange

  fake.short_transfer = true;
  const ExchangeStatus s = driver.Exchange({1, 2, 3, 4}, in);
  EXPECT_EQ(s.code, ExchangeStatus::Code::kFault);
  EXPECT_STREQ(s.reason, "spidev transferred fewer than 24 bytes (request and fetch)");
  fake.short_transfer = false;
  fake.fail_request = SPI_IOC_MESSAGE(2);
  fake.fail_errno = EIO;
  EXPECT_EQ(driver.Exchange({1, 2, 3, 4}, in).code, ExchangeStatus::Code::kFault);
  EXPECT_EQ(bus.last_errno(), EIO);
  // A single transfer is still one 12-byte SPI_IOC_MESSAGE(1).
  fake.fail_request = 0;
  FrameBytes tx{};
  FrameBytes rx{};
  EXPECT_EQ(bus.Transfer(tx, rx).result, BusResult::kOk);
  EXPECT_EQ(fake.requests.back(), SPI_IOC_MESSAGE(1));
  EXPECT_EQ(fake.last.len, 12U);
  EXPECT_EQ(fake.last.cs_change, 0);
  fake.fail_request = SPI_IOC_MESSAGE(1);
  EXPECT_EQ(bus.Transfer(tx, rx).result, BusResult::kIoError);
}

TEST(SpidevBus, ExchangeMessageComposition) {
  SpidevConfig config;
  config.speed_hz = 20'000'000;
  config.bits_per_word = 8;
  const FrameBytes request{1, 2, 3};
  const FrameBytes fetch{0, 3};
  FrameBytes request_miso{};
  FrameBytes answer{};
  std::array<spi_ioc_transfer, 2> message;
  std::memset(message.data(), 0xA5, sizeof message);  // every field must be written
  ComposeExchangeMessage(config, request, request_miso, fetch, answer, message);
  EXPECT_EQ(message[0].tx_buf, reinterpret_cast<std::uintptr_t>(request.data()));
  EXPECT_EQ(message[0].rx_buf, reinterpret_cast<std::uintptr_t>(request_miso.data()));
  EXPECT_EQ(message[1].tx_buf, reinterpret_cast<std::uintptr_t>(fetch.data()));
  EXPECT_EQ(message[1].rx_buf, reinterpret_cast<std::uintptr_t>(answer.data()));
  for (const spi_ioc_transfer& t : message) {
    EXPECT_EQ(t.len, 12U);
    EXPECT_EQ(t.speed_hz, 20'000'000U);
    EXPECT_EQ(t.bits_per_word, 8);
    EXPECT_EQ(t.tx_nbits, 0);
    EXPECT_EQ(t.rx_nbits, 0);
    EXPECT_EQ(t.word_delay_usecs, 0);
    EXPECT_EQ(t.pad, 0);
  }
  EXPECT_EQ(message[0].cs_change, 1);
  EXPECT_EQ(message[0].delay_usecs, 2);
  EXPECT_GE(std::int64_t{message[0].delay_usecs} * 1000, kFetchGapNs);
  EXPECT_EQ(message[1].cs_change, 0);
  EXPECT_EQ(message[1].delay_usecs, 0);
}

TEST(SpidevBus, SetUpFailuresSayWhatAndWhatToDo) {
  FakeSpidev missing;
  missing.fail_open = ENOENT;
  try {
    SpidevBus bus("/dev/spidev9.9", SpidevConfig{}, missing);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/dev/spidev9.9"), std::string::npos) << what;
    EXPECT_NE(what.find(std::strerror(ENOENT)), std::string::npos) << what;
    EXPECT_NE(what.find("dtparam=spi=on"), std::string::npos) << what;
  }
  FakeSpidev refuses;
  refuses.fail_request = SPI_IOC_WR_MAX_SPEED_HZ;
  refuses.fail_errno = EINVAL;
  try {
    SpidevBus bus("/dev/spidev0.0", SpidevConfig{}, refuses);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("set SPI speed"), std::string::npos) << e.what();
  }
  EXPECT_EQ(refuses.closed, std::vector<int>{42});  // no descriptor leaks
}

}  // namespace
}  // namespace hiltwin::io
