// The telemetry flags (sinks.h): parsed and checked before anything opens, then turned into
// the session's TelemetryConfig. Every message names the flag, the value and the fix.
#include <charconv>
#include <cstdlib>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

/// ROS 2 topic names stay short; a bound keeps every UDP datagram below 2 KB.
constexpr std::size_t kMaxNamespaceChars = 100;
/// ROS_DOMAIN_ID's range (Cyclone maps domains to ports up to 232).
constexpr std::uint32_t kMaxDomain = 232;

[[noreturn]] void Bad(const std::string& message) { throw std::invalid_argument(message); }

/// A whole decimal number in [low, high], or nullopt.
std::optional<std::uint32_t> ParseUint(std::string_view text, std::uint32_t low,
                                       std::uint32_t high) {
  std::uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || value < low ||
      value > high) {
    return std::nullopt;
  }
  return value;
}

/// "HOST:PORT" -> (host, port); `flag` names the flag in messages.
std::pair<std::string, std::uint16_t> HostPort(const std::string& text, const std::string& flag) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    Bad(flag + " '" + text + "': expected HOST:PORT, e.g. 127.0.0.1:9870");
  }
  const auto port = ParseUint(std::string_view(text).substr(colon + 1), 1, 65535);
  if (!port) Bad(flag + " '" + text + "': the port must be a whole number from 1 to 65535");
  return {text.substr(0, colon), static_cast<std::uint16_t>(*port)};
}

bool IsKind(const std::string& spec, std::string_view kind) {
  return spec == kind || (spec.size() > kind.size() && spec.compare(0, kind.size(), kind) == 0 &&
                          spec[kind.size()] == ':');
}

// Read once per call, on the control thread, before any helper thread of ours exists.
const char* RosDomainIdText() {
  return std::getenv("ROS_DOMAIN_ID");  // NOLINT(concurrency-mt-unsafe)
}

void CheckKinds(const std::vector<std::string>& specs) {
  for (const std::string& spec : specs) {
    if (!IsKind(spec, "dds") && !IsKind(spec, "udp")) {
      Bad("--telemetry '" + spec + "': unknown kind; use dds[:DOMAIN] or udp[:HOST:PORT]");
    }
  }
}

}  // namespace

std::uint32_t DefaultDdsDomain(const std::string& flag) {
  const char* text = RosDomainIdText();
  // ROS 2 (rcutils) reads an empty variable as an unset one.
  if (text == nullptr || *text == '\0') return 0;
  const auto domain = ParseUint(text, 0, kMaxDomain);
  if (!domain) {
    Bad("ROS_DOMAIN_ID='" + std::string(text) +
        "' (the DDS domain when none is given) is not a domain: set it to a whole number from 0 "
        "to " +
        std::to_string(kMaxDomain) + ", unset it (domain 0), or give the domain with " + flag);
  }
  return *domain;
}

std::vector<DdsEndpoint> ParseDdsSpecs(const std::vector<std::string>& specs) {
  CheckKinds(specs);
  std::vector<DdsEndpoint> endpoints;
  std::set<std::uint32_t> seen;
  for (const std::string& spec : specs) {
    if (!IsKind(spec, "dds")) continue;
    DdsEndpoint endpoint;
    if (spec.size() == 3) {
      endpoint.domain = DefaultDdsDomain("--telemetry dds:N");
    } else {
      const auto domain = ParseUint(std::string_view(spec).substr(4), 0, kMaxDomain);
      if (!domain) {
        Bad("--telemetry '" + spec + "': the DDS domain must be a whole number from 0 to " +
            std::to_string(kMaxDomain) + " (as ROS_DOMAIN_ID)");
      }
      endpoint.domain = *domain;
    }
    if (!seen.insert(endpoint.domain).second) {
      Bad("--telemetry '" + spec + "': DDS domain " + std::to_string(endpoint.domain) +
          (spec.size() == 3 ? " (ROS_DOMAIN_ID)" : "") + " is given twice; give each domain once");
    }
    endpoints.push_back(endpoint);
  }
  return endpoints;
}

std::vector<UdpEndpoint> ParseUdpSpecs(const std::vector<std::string>& specs) {
  CheckKinds(specs);
  std::vector<UdpEndpoint> endpoints;
  for (const std::string& spec : specs) {
    if (!IsKind(spec, "udp")) continue;
    UdpEndpoint endpoint;
    if (spec.size() > 3) {
      std::tie(endpoint.host, endpoint.port) = HostPort(spec.substr(4), "--telemetry udp:");
    }
    endpoints.push_back(endpoint);
  }
  return endpoints;
}

WebEndpoint ParseWebSpec(const std::string& spec) {
  WebEndpoint endpoint;
  if (spec.find(':') == std::string::npos) {  // a bare port
    const auto port = ParseUint(spec, 1, 65535);
    if (!port) Bad("--web '" + spec + "': expected ADDR:PORT (e.g. 127.0.0.1:8080) or a port");
    endpoint.port = static_cast<std::uint16_t>(*port);
    return endpoint;
  }
  std::tie(endpoint.address, endpoint.port) = HostPort(spec, "--web");
  return endpoint;
}

void CheckAcceptCommands(const TelemetryOptions& options) {
  if (options.accept_commands && ParseDdsSpecs(options.specs).empty()) {
    Bad("--accept-commands: commands come over DDS only; add --telemetry dds[:DOMAIN], or drop "
        "--accept-commands");
  }
}

void CheckNamespace(const std::string& ns) {
  if (ns.empty()) Bad("--namespace: empty; give a name such as bench1 or lab/bench1");
  if (ns.size() > kMaxNamespaceChars) {
    Bad("--namespace '" + ns + "': longer than " + std::to_string(kMaxNamespaceChars) +
        " characters");
  }
  bool token_start = true;
  for (std::size_t i = 0; i < ns.size(); ++i) {
    const char c = ns[i];
    const bool alpha = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    const bool digit = c >= '0' && c <= '9';
    const bool ok =
        c == '/' ? !token_start && i + 1 < ns.size() : (alpha || (digit && !token_start));
    if (!ok) {
      Bad("--namespace '" + ns + "': character " + std::to_string(i + 1) + " ('" +
          std::string(1, c) +
          "') does not fit a ROS 2 name: use letters, digits and '_' in parts separated by "
          "single '/', each part starting with a letter or '_', no leading or trailing '/'");
    }
    token_start = c == '/';
  }
}

runtime::TelemetryConfig MakeTelemetryConfig(const TelemetryOptions& options) {
  runtime::TelemetryConfig config;
  CheckAcceptCommands(options);
  std::vector<DdsEndpoint> dds = ParseDdsSpecs(options.specs);
  for (DdsEndpoint& endpoint : dds) endpoint.accept_commands = options.accept_commands;
  const std::vector<UdpEndpoint> udp = ParseUdpSpecs(options.specs);
  std::optional<WebEndpoint> web;
  if (!options.web.empty()) web = ParseWebSpec(options.web);
  if (dds.empty() && udp.empty() && !web) return config;  // off: nothing else is checked
  CheckNamespace(options.ns);
  if (!(options.rate_hz > 0.0 && options.rate_hz <= 1000.0)) {
    Bad("--telemetry-rate " + std::to_string(options.rate_hz) +
        ": give a rate above 0 and at most 1000 Hz (default 50)");
  }
  config.rate_hz = options.rate_hz;
  config.ns = options.ns;
  // Cheapest to open first: a port in use fails before a DDS participant starts.
  if (web) config.sinks.push_back(MakeWebSink(*web));
  for (const UdpEndpoint& endpoint : udp) config.sinks.push_back(MakeUdpSink(endpoint));
  for (const DdsEndpoint& endpoint : dds) config.sinks.push_back(MakeDdsSink(endpoint));
  return config;
}

}  // namespace hiltwin::telemetry
