// Placeholder until the web sink lands (removed by that change).
#include <stdexcept>

#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {

std::shared_ptr<runtime::TelemetrySink> MakeWebSink(const WebEndpoint&) {
  throw std::runtime_error("the web page is not built yet");
}

}  // namespace hiltwin::telemetry
