// Placeholder until the DDS sink and monitor land (removed by that change).
#include <stdexcept>

#include "hiltwin/telemetry/dds_monitor.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {

std::shared_ptr<runtime::TelemetrySink> MakeDdsSink(const DdsEndpoint&) {
  throw std::runtime_error("DDS telemetry is not built yet");
}
struct DdsMonitor::State {};
DdsMonitor::DdsMonitor(std::uint32_t) : state_(nullptr) {
  throw std::runtime_error("DDS monitor is not built yet");
}
DdsMonitor::~DdsMonitor() = default;
std::vector<MonitorEntry> DdsMonitor::Poll() { return {}; }
std::string DdsMonitor::SendCommand(const std::string&, runtime::RemoteCommand, double) {
  return "not built";
}

}  // namespace hiltwin::telemetry
