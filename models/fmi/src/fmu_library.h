#pragma once
// An FMU's shared library, loaded with every function hiltwin calls looked up.

#include <filesystem>
#include <string>
#include <string_view>

#include "fmu_archive.h"
#include "hiltwin/fmi/fmi2_abi.h"

namespace hiltwin::fmi {

/// The FMI 2.0 functions hiltwin calls, all non-null once FmuLibrary is built.
struct Fmi2Functions {
  fmi2GetVersionTYPE* get_version = nullptr;
  fmi2GetTypesPlatformTYPE* get_types_platform = nullptr;
  fmi2InstantiateTYPE* instantiate = nullptr;
  fmi2FreeInstanceTYPE* free_instance = nullptr;
  fmi2SetupExperimentTYPE* setup_experiment = nullptr;
  fmi2EnterInitializationModeTYPE* enter_initialization_mode = nullptr;
  fmi2ExitInitializationModeTYPE* exit_initialization_mode = nullptr;
  fmi2TerminateTYPE* terminate = nullptr;
  fmi2ResetTYPE* reset = nullptr;
  fmi2GetRealTYPE* get_real = nullptr;
  fmi2SetRealTYPE* set_real = nullptr;
  fmi2DoStepTYPE* do_step = nullptr;
};

class FmuLibrary {
 public:
  /// dlopens `<unpacked>/binaries/<kFmuPlatform>/<model_identifier>.so` (RTLD_NOW | RTLD_LOCAL:
  /// every undefined symbol is found now, before the run, and two FMUs never see each other's
  /// symbols), looks up every function and checks fmi2GetVersion is "2.0". Throws
  /// plant::PlantError naming the file and the symbol (and, without the binary, the platforms
  /// the archive has binaries for).
  FmuLibrary(const UnpackedFmu& unpacked, std::string_view model_identifier,
             std::string_view fmu_name);
  ~FmuLibrary();
  FmuLibrary(const FmuLibrary&) = delete;
  FmuLibrary& operator=(const FmuLibrary&) = delete;

  [[nodiscard]] const Fmi2Functions& functions() const noexcept { return functions_; }
  [[nodiscard]] const std::string& entry() const noexcept { return entry_; }

 private:
  void LookUpAll(std::string_view fmu_name);

  void* handle_ = nullptr;
  std::string entry_;  ///< "binaries/linux64/<id>.so" (fmu_platform.h), as named in messages
  Fmi2Functions functions_;
};

}  // namespace hiltwin::fmi
