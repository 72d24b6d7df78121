#pragma once
// A UDP socket bound to a free loopback port, for tests of the telemetry stream.

#include <cstdint>
#include <string>

namespace hiltwin::test {

class UdpListener {
 public:
  UdpListener();  ///< binds 127.0.0.1 on a port the kernel picks
  ~UdpListener();
  UdpListener(const UdpListener&) = delete;
  UdpListener& operator=(const UdpListener&) = delete;

  [[nodiscard]] std::uint16_t port() const { return port_; }
  /// The next datagram, or "" when none arrives within `timeout_ms`.
  [[nodiscard]] std::string Receive(int timeout_ms) const;

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

}  // namespace hiltwin::test
