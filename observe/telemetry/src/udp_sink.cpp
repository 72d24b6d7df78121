// PlotJuggler's UDP stream (sinks.h): one JSON object per datagram, {"timestamp": t, "<ns>":
// {the record}}, so several tasks sending to one PlotJuggler port appear as separate trees
// (/twin/pose/x, /controller/wheels/...). Sent without blocking: a datagram the kernel cannot
// take at once is dropped, which is what a live plot wants.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include "hiltwin/telemetry/record_json.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

/// Datagrams stay below this (the bound; PlotJuggler reads up to 64 KiB).
constexpr std::size_t kMaxDatagramBytes = 2048;

class UdpSink final : public runtime::TelemetrySink {
 public:
  explicit UdpSink(const UdpEndpoint& endpoint) : endpoint_(endpoint) {
    address_.sin_family = AF_INET;
    address_.sin_port = htons(endpoint.port);
    if (inet_pton(AF_INET, endpoint.host.c_str(), &address_.sin_addr) != 1) {
      throw std::invalid_argument("--telemetry udp:" + endpoint.host + ":" +
                                  std::to_string(endpoint.port) +
                                  ": the host must be a numeric IPv4 address, e.g. 127.0.0.1");
    }
    socket_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (socket_ < 0) {
      throw std::runtime_error(std::string("--telemetry udp: cannot open a UDP socket: ") +
                               std::strerror(errno));
    }
  }
  ~UdpSink() override { ::close(socket_); }
  UdpSink(const UdpSink&) = delete;
  UdpSink& operator=(const UdpSink&) = delete;

  void Open(const runtime::TelemetryShape& shape, const std::string& ns) override {
    static_cast<void>(shape);
    ns_ = ns;
  }

  void Publish(const runtime::TelemetryRecord& record) noexcept override {
    try {
      nlohmann::ordered_json body = ToJson(record);
      body.erase("timestamp");
      const nlohmann::ordered_json datagram = {{"timestamp", record.time_s}, {ns_, body}};
      const std::string text = datagram.dump();
      if (text.size() > kMaxDatagramBytes) return;  // cannot happen with a checked namespace
      // MSG_DONTWAIT: never wait for socket buffer space on the telemetry thread.
      static_cast<void>(::sendto(socket_, text.data(), text.size(), MSG_DONTWAIT,
                                 reinterpret_cast<const sockaddr*>(&address_), sizeof(address_)));
    } catch (...) {
      // Out of memory while formatting: this record is not sent; the next one may be.
    }
  }

  [[nodiscard]] std::string Describe() const override {
    return "PlotJuggler UDP " + endpoint_.host + ":" + std::to_string(endpoint_.port);
  }

 private:
  UdpEndpoint endpoint_;
  sockaddr_in address_{};
  int socket_ = -1;
  std::string ns_;
};

}  // namespace

std::shared_ptr<runtime::TelemetrySink> MakeUdpSink(const UdpEndpoint& endpoint) {
  return std::make_shared<UdpSink>(endpoint);
}

}  // namespace hiltwin::telemetry
