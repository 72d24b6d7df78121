// Every controller `--controller SPEC` can name (hiltwin/runs/controllers.h).
#include "hiltwin/runs/controllers.h"

#include "hiltwin/controller/abi_controller.h"
#include "hiltwin/controller/twentysim_controller.h"
#include "hiltwin/fmi/fmu_controller.h"
#include "hiltwin/relbot/pid_controller.h"

namespace hiltwin::app {

void RegisterControllers() {
  RegisterPidController();                        // `pid`, the built-in position PID: the default
  controller::RegisterLibControllerKind();        // lib:PATH.so, the C ABI
  controller::RegisterTwentySimControllerKind();  // 20sim:NAME, models/controllers/<NAME>
  fmi::RegisterFmuControllerKind();               // fmu:PATH.fmu
}

}  // namespace hiltwin::app
