// Every controller `--controller SPEC` can name (hiltwin/runs/controllers.h).
#include "hiltwin/runs/controllers.h"

#include "hiltwin/relbot/pid_controller.h"

namespace hiltwin::app {

void RegisterControllers() {
  RegisterPidController();  // `pid`, the built-in position PID: the default
}

}  // namespace hiltwin::app
