#pragma once
/// `--controller lib:PATH.so`: a controller in a shared library with the C ABI of
/// hiltwin/controller_abi.h (docs/controller-abi.md). The library is opened with
/// dlopen(RTLD_NOW | RTLD_LOCAL), so every symbol it needs is found before the run and two
/// controllers never see each other's symbols; its descriptor is checked in full (ABI version,
/// entry points, port names and units) before anything of it is called, and every refusal is a
/// ControllerError naming the file, what is wrong and what to do.
///
/// Start(step_s) calls create() then start(step_s). Step() is one call of step(); nonzero is
/// ControllerStatus::Error with a copy of the library's last_error() text (its first 255
/// bytes), which stays valid after Finish, until the controller is destroyed. Finish() calls
/// finish() once and destroy(); the library is closed when the controller is destroyed.
/// hiltwin does not check the outputs here: the ECS's controller task does (a NaN passes
/// through unchanged).
/// A crash in the library's code (a null dereference) ends the process, by design: the twin
/// goes safe as for any ECS that dies.

#include <memory>
#include <string>

#include "hiltwin/controller/controller.h"

namespace hiltwin::controller {

/// The kind name of ControllerInfo::kind for these controllers.
inline constexpr const char* kAbiControllerKind = "C ABI shared library";

/// Opens the library at `path` (relative to the working directory, as typed after `lib:`) and
/// checks its descriptor. Not started. Throws ControllerError.
[[nodiscard]] std::unique_ptr<Controller> LoadAbiController(const std::string& path);

/// Registers the `lib` kind (controller_registry.h) with LoadAbiController as its loader. A
/// `lib:` controller takes no options: --gains is refused, naming the controller.
void RegisterLibControllerKind();

}  // namespace hiltwin::controller
