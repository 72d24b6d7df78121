#include "web_bind.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <system_error>

namespace hiltwin::telemetry::web {
namespace {

// Closes the probe socket on every path.
class Fd {
 public:
  explicit Fd(int fd) noexcept : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  [[nodiscard]] int get() const noexcept { return fd_; }

 private:
  int fd_;
};

int ProbeOne(const addrinfo& ai) {
  const Fd fd(socket(ai.ai_family, ai.ai_socktype, ai.ai_protocol));
  if (fd.get() < 0) return errno;
  const int yes = 1;
  setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  // listen too: with SO_REUSEADDR a bind can succeed next to a socket that is bound but not
  // yet listening, and httplib's listen then fails.
  if (bind(fd.get(), ai.ai_addr, ai.ai_addrlen) != 0) return errno;
  if (listen(fd.get(), 1) != 0) return errno;
  return 0;
}

}  // namespace

int ProbeBind(const WebEndpoint& endpoint) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(endpoint.port);
  if (getaddrinfo(endpoint.address.c_str(), port.c_str(), &hints, &found) != 0) return -1;
  int error = 0;
  for (const addrinfo* ai = found; ai != nullptr; ai = ai->ai_next) {
    error = ProbeOne(*ai);
    if (error == 0) break;  // httplib takes the first address that binds, too
  }
  freeaddrinfo(found);
  return error;
}

std::string BindFailureMessage(const WebEndpoint& endpoint, int probe_error) {
  const std::string port = std::to_string(endpoint.port);
  const std::string flag = "--web " + endpoint.address + ":" + port + ": ";
  switch (probe_error) {
    case EADDRINUSE:
      return flag + "port " + port +
             " is already in use (another hiltwin or server?); pick another with --web "
             "ADDR:PORT";
    case EADDRNOTAVAIL:
      return flag + endpoint.address +
             " is not an address of this machine; use 127.0.0.1 (this machine only) or 0.0.0.0 "
             "(every interface)";
    case EACCES:
      return flag + "port " + port +
             " needs privileges (ports below 1024); pick one from 1024 up with --web ADDR:PORT";
    case -1:
      return flag + "'" + endpoint.address +
             "' is neither an IP address nor a known host name; give a numeric address such "
             "as 127.0.0.1";
    case 0:  // freed between httplib's try and the probe
      return flag + "could not bind port " + port + "; try again or pick another port";
    default:
      return flag + "could not bind port " + port + " (" +
             std::system_category().message(probe_error) + "); pick another with --web ADDR:PORT";
  }
}

std::optional<WebEndpoint> BoundEndpoint(int fd) {
  sockaddr_storage addr{};
  socklen_t length = sizeof(addr);
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length) != 0) return std::nullopt;
  std::array<char, NI_MAXHOST> host{};
  std::array<char, NI_MAXSERV> port{};
  if (getnameinfo(reinterpret_cast<const sockaddr*>(&addr), length, host.data(), host.size(),
                  port.data(), port.size(), NI_NUMERICHOST | NI_NUMERICSERV) != 0) {
    return std::nullopt;
  }
  return WebEndpoint{host.data(), static_cast<std::uint16_t>(std::stoi(port.data()))};
}

std::string UrlOf(const WebEndpoint& endpoint) {
  const bool v6 = endpoint.address.find(':') != std::string::npos;
  const std::string host = v6 ? "[" + endpoint.address + "]" : endpoint.address;
  return "http://" + host + ":" + std::to_string(endpoint.port) + "/";
}

bool IsEveryInterface(const std::string& address) {
  return address == "0.0.0.0" || address == "::";
}

}  // namespace hiltwin::telemetry::web
