#include "hiltwin/runtime/telemetry.h"

namespace hiltwin::runtime {

const char* ToString(RemoteCommand command) noexcept {
  switch (command) {
    case RemoteCommand::kInitialise:
      return "INITIALISE";
    case RemoteCommand::kStart:
      return "START";
    case RemoteCommand::kStop:
      return "STOP";
    case RemoteCommand::kReset:
      return "RESET";
    case RemoteCommand::kPause:
      return "PAUSE";
    case RemoteCommand::kQuit:
      return "QUIT";
  }
  return "unknown";
}

std::optional<RemoteCommand> RemoteCommandOf(std::int32_t code) noexcept {
  if (code < static_cast<std::int32_t>(RemoteCommand::kInitialise) ||
      code > static_cast<std::int32_t>(RemoteCommand::kQuit)) {
    return std::nullopt;
  }
  return static_cast<RemoteCommand>(code);
}

}  // namespace hiltwin::runtime
