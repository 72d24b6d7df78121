#pragma once
/// The ways telemetry leaves a session (runtime/telemetry.h): DDS topics with ROS 2 names and
/// types, PlotJuggler's UDP/JSON stream, and the live web page. Each factory acquires what can
/// fail for a user's reason (a participant on a domain, a bound port) at once, so a command
/// that asks for it fails before its run starts; the messages name the flag and the fix.
/// docs/telemetry.md documents every topic, field and flag.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hiltwin/runtime/telemetry.h"

namespace hiltwin::telemetry {

/// `--telemetry dds[:DOMAIN]`: publishes rt/<ns>/pose (geometry_msgs::msg::dds_::Pose2D_),
/// rt/<ns>/joint_states (sensor_msgs::msg::dds_::JointState_), rt/<ns>/timing
/// (hiltwin_msgs::msg::dds_::Timing_) and reads rt/<ns>/command (std_msgs::msg::dds_::Int32_).
/// Warns once on stderr when another task publishes under the same namespace.
struct DdsEndpoint {
  std::uint32_t domain = 0;  ///< DDS domain id (0..232; a bare `dds`: ROS_DOMAIN_ID)
  /// --accept-commands: commands on rt/<ns>/command reach the session. Off, the sink refuses
  /// them (it says so once on stderr, and the sender sees it in the reader's user data).
  bool accept_commands = false;
};
/// Throws std::invalid_argument (bad domain) or std::runtime_error (Cyclone refused).
[[nodiscard]] std::shared_ptr<runtime::TelemetrySink> MakeDdsSink(const DdsEndpoint& endpoint);

/// `--telemetry udp[:HOST:PORT]`: one JSON object per datagram (PlotJuggler's UDP server).
struct UdpEndpoint {
  std::string host = "127.0.0.1";  ///< numeric IPv4 address
  std::uint16_t port = 9870;       ///< PlotJuggler's default
};
[[nodiscard]] std::shared_ptr<runtime::TelemetrySink> MakeUdpSink(const UdpEndpoint& endpoint);

/// `--web [ADDR:PORT]`: the live page and its Server-Sent Events stream.
struct WebEndpoint {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8080;
};
/// Binds the port now: throws std::invalid_argument naming the port when it is in use or the
/// address is not this machine's.
[[nodiscard]] std::shared_ptr<runtime::TelemetrySink> MakeWebSink(const WebEndpoint& endpoint);

/// The parsed telemetry flags of a command.
struct TelemetryOptions {
  std::vector<std::string> specs;  ///< --telemetry, repeatable: dds[:DOMAIN] | udp[:HOST:PORT]
  std::string ns;                  ///< --namespace
  std::string web;                 ///< --web ADDR:PORT, "" for none (the flag's bare form
                                   ///< gives "127.0.0.1:8080")
  double rate_hz = 50.0;           ///< --telemetry-rate
  bool accept_commands = false;    ///< --accept-commands (DDS only)
};

/// The DDS domain when a flag names none, as for every ROS 2 tool: ROS_DOMAIN_ID, or 0 when it
/// is unset or empty. Throws std::invalid_argument naming the variable, its value and `flag`
/// (how to give a domain instead, e.g. "--domain N") when it is not a whole number from 0 to
/// 232: never a silent 0.
[[nodiscard]] std::uint32_t DefaultDdsDomain(const std::string& flag);
/// Parses the specs without opening anything (a bare `dds` is DefaultDdsDomain()); throws
/// std::invalid_argument naming the flag.
[[nodiscard]] std::vector<DdsEndpoint> ParseDdsSpecs(const std::vector<std::string>& specs);
[[nodiscard]] std::vector<UdpEndpoint> ParseUdpSpecs(const std::vector<std::string>& specs);
[[nodiscard]] WebEndpoint ParseWebSpec(const std::string& spec);
/// --accept-commands applies to DDS only: throws std::invalid_argument naming the flag when it
/// is given without a `dds` spec.
void CheckAcceptCommands(const TelemetryOptions& options);
/// A ROS 2 namespace without its leading slash: [A-Za-z_][A-Za-z0-9_]* tokens joined by '/'.
/// Throws std::invalid_argument naming --namespace and the offending character.
void CheckNamespace(const std::string& ns);

/// The session's telemetry configuration: checks everything, then opens every sink (exit 2 on
/// a bad flag or a port in use). An empty result (no flag given) costs the loop nothing.
[[nodiscard]] runtime::TelemetryConfig MakeTelemetryConfig(const TelemetryOptions& options);

}  // namespace hiltwin::telemetry
