// The `lib:` kind of --controller (abi_controller.h). Its own unit, so a program that only
// loads libraries (the tests, the probe) does not need the registry linked.
#include "hiltwin/controller/abi_controller.h"
#include "hiltwin/controller/controller_registry.h"

namespace hiltwin::controller {

void RegisterLibControllerKind() {
  RegisterControllerKind(ControllerKind{
      "lib", "a shared library with the C ABI of hiltwin/controller_abi.h (lib:PATH.so)",
      [](const std::string& path, const ControllerOptions& options) {
        if (!options.gains_path.empty()) {
          throw ControllerError("controller lib:" + path + ": --gains sets the built-in " +
                                "PID's gains, not a library's: leave it out");
        }
        return LoadAbiController(path);
      }});
}

}  // namespace hiltwin::controller
