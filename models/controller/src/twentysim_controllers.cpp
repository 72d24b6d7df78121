// The 20-sim controllers built in (hiltwin_add_20sim_controller) and the `20sim` kind that
// finds them: `--controller 20sim:NAME`.
#include <algorithm>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/controller/controller_registry.h"
#include "hiltwin/controller/twentysim_controller.h"

namespace hiltwin::controller {
namespace {

// Filled during static initialisation (one registration file per 20-sim controller), read
// after; a function-local static, so it exists before the first registration whatever the
// order in which the translation units initialise.
std::vector<std::string>& Names() {
  static std::vector<std::string> names;
  return names;
}

std::string KnownList() {
  const std::vector<std::string> names = TwentySimControllerNames();
  if (names.empty()) {
    return "none is built in: add one with hiltwin_add_20sim_controller in "
           "models/controllers/CMakeLists.txt (docs/20sim.md, \"20-sim controllers\")";
  }
  std::string list = "built in: ";
  for (std::size_t i = 0; i < names.size(); ++i) list += (i == 0 ? "" : ", ") + names[i];
  return list;
}

std::unique_ptr<Controller> Load(const std::string& name, const ControllerOptions& options) {
  const std::vector<std::string>& names = Names();
  if (std::find(names.begin(), names.end(), name) != names.end()) {
    if (const ControllerEntry* entry = FindController(name)) return entry->make(options);
  }
  throw ControllerError("--controller 20sim:" + name + ": no 20-sim controller '" + name + "' (" +
                        KnownList() + ")");
}

}  // namespace

bool RegisterTwentySimController(ControllerEntry entry) {
  RegisterTwentySimControllerKind();
  Names().push_back(entry.name);
  return RegisterController(std::move(entry));
}

void RegisterTwentySimControllerKind() {
  static std::once_flag once;
  std::call_once(once, [] {
    RegisterControllerKind({"20sim",
                            "a 20-sim C++ class for 20-sim submodel built into hiltwin "
                            "(hiltwin_add_20sim_controller)",
                            &Load, "NAME"});
  });
}

std::vector<std::string> TwentySimControllerNames() {
  std::vector<std::string> names = Names();
  std::sort(names.begin(), names.end());
  return names;
}

void RefuseTwentySimControllerOptions(const ControllerOptions& options, std::string_view name,
                                      std::string_view class_name) {
  if (options.gains_path.empty()) return;
  std::string message = "--gains " + options.gains_path + " cannot be honoured: the 20-sim ";
  message.append("controller '").append(name).append("' has its gains compiled in: change ");
  message.append("them in 20-sim and regenerate, or edit the parameters m_P[] in ");
  message.append(class_name).append(".cpp's Initialize (docs/20sim.md)");
  throw ControllerError(message);
}

}  // namespace hiltwin::controller
