// Every controller `--controller SPEC` can name, and the one place one is made from the flags
// (hiltwin/runs/controllers.h).
#include "hiltwin/runs/controllers.h"

#include <utility>

#include "hiltwin/controller/abi_controller.h"
#include "hiltwin/controller/controller_registry.h"
#include "hiltwin/controller/twentysim_controller.h"
#include "hiltwin/fmi/fmu_controller.h"
#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/pid_controller.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/runs/command.h"

namespace hiltwin::app {

void RegisterControllers() {
  RegisterPidController();                        // `pid`, the built-in position PID: the default
  controller::RegisterLibControllerKind();        // lib:PATH.so, the C ABI
  controller::RegisterTwentySimControllerKind();  // 20sim:NAME, models/controllers/<NAME>
  fmi::RegisterFmuControllerKind();               // fmu:PATH.fmu
}

/// --gains belongs to the built-in PID: another controller would silently ignore it.
void CheckGainsFlag(const ControllerFlags& flags) {
  if (flags.gains_path.empty() || flags.spec == kPidControllerName) return;
  ThrowUsage("--gains " + flags.gains_path + " gives the built-in PID's gains, but --controller " +
             flags.spec + " is another controller: drop --gains (its gains are its own), or " +
             "use --controller pid");
}

BoundController MakeBoundController(const ControllerFlags& flags) {
  CheckGainsFlag(flags);
  RegisterControllers();
  try {
    BoundController made;
    made.controller = controller::MakeController(flags.spec, {flags.gains_path, flags.config_path});
    const controller::ControllerMap map =
        flags.map_path.empty()
            ? RelbotControllerMap(WheelGeometryOf(flags.config_path.empty()
                                                      ? DefaultRelbotParams()
                                                      : LoadRelbotParams(flags.config_path)))
            : controller::LoadControllerMap(flags.map_path);
    made.map_source = map.source;
    made.map = controller::BindControllerMap(map, *made.controller);
    return made;
  } catch (const controller::ControllerError& e) {
    ThrowUsage(e.what());
  } catch (const controller::ControllerMapError& e) {
    ThrowUsage(e.what());
  } catch (const ConfigError& e) {
    ThrowUsage(e.what());
  }
}

}  // namespace hiltwin::app
