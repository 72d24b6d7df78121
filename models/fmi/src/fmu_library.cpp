// dlopen/dlsym of an FMU's binary.
#include "fmu_library.h"

#include <dlfcn.h>

#include <cstring>
#include <string>
#include <system_error>

#include "hiltwin/fmi/fmu_platform.h"
#include "hiltwin/plant/plant.h"

namespace hiltwin::fmi {
namespace {

using plant::PlantError;

template <typename Function>
void LookUp(void* handle, const char* symbol, Function*& out, const std::string& where) {
  // dlerror's state is per thread in glibc, which is all the lookup needs.
  dlerror();  // NOLINT(concurrency-mt-unsafe): clear, so a stale error is not taken for ours
  void* address = dlsym(handle, symbol);
  if (address == nullptr) {
    throw PlantError(where + " does not export " + symbol + ", a function every FMI 2.0 " +
                     "co-simulation FMU has: export the FMU again, or report it to the tool " +
                     "that made it");
  }
  // dlsym returns object pointers; POSIX guarantees the function pointer conversion.
  out = reinterpret_cast<Function*>(address);
}

}  // namespace

FmuLibrary::FmuLibrary(const UnpackedFmu& unpacked, std::string_view model_identifier,
                       std::string_view fmu_name)
    : entry_("binaries/" + std::string(kFmuPlatform) + "/" + std::string(model_identifier) +
             ".so") {
  const std::filesystem::path file = unpacked.dir() / entry_;
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) {
    throw PlantError(std::string(fmu_name) + ": no " + entry_ + " in the archive (binaries " +
                     "for: " + unpacked.binary_platforms() + "); hiltwin needs the " +
                     std::string(kFmuPlatformName) + " binary named after <CoSimulation " +
                     "modelIdentifier>: export the FMU with " + std::string(kFmuPlatform) +
                     " binaries");
  }
  handle_ = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle_ == nullptr) {
    const char* why = dlerror();  // NOLINT(concurrency-mt-unsafe): per thread in glibc
    throw PlantError(std::string(fmu_name) + ": " + entry_ + " cannot be loaded (" +
                     (why != nullptr ? why : "dlopen failed") + "): it must be a " +
                     std::string(kFmuPlatformName) + " shared library whose dependencies are " +
                     "installed");
  }
  try {
    LookUpAll(fmu_name);
  } catch (...) {
    dlclose(handle_);
    throw;
  }
}

void FmuLibrary::LookUpAll(std::string_view fmu_name) {
  const std::string where = std::string(fmu_name) + ": " + entry_;
  LookUp(handle_, "fmi2GetVersion", functions_.get_version, where);
  LookUp(handle_, "fmi2GetTypesPlatform", functions_.get_types_platform, where);
  LookUp(handle_, "fmi2Instantiate", functions_.instantiate, where);
  LookUp(handle_, "fmi2FreeInstance", functions_.free_instance, where);
  LookUp(handle_, "fmi2SetupExperiment", functions_.setup_experiment, where);
  LookUp(handle_, "fmi2EnterInitializationMode", functions_.enter_initialization_mode, where);
  LookUp(handle_, "fmi2ExitInitializationMode", functions_.exit_initialization_mode, where);
  LookUp(handle_, "fmi2Terminate", functions_.terminate, where);
  LookUp(handle_, "fmi2Reset", functions_.reset, where);
  LookUp(handle_, "fmi2GetReal", functions_.get_real, where);
  LookUp(handle_, "fmi2SetReal", functions_.set_real, where);
  LookUp(handle_, "fmi2DoStep", functions_.do_step, where);
  const char* version = functions_.get_version();
  if (version == nullptr || std::strcmp(version, HILTWIN_FMI2_VERSION) != 0) {
    throw PlantError(where + ": fmi2GetVersion returned \"" +
                     (version != nullptr ? version : "(null)") + "\", not \"2.0\": the " +
                     "binary does not match its FMI 2.0 model description");
  }
  const char* platform = functions_.get_types_platform();
  if (platform == nullptr || std::strcmp(platform, HILTWIN_FMI2_TYPES_PLATFORM) != 0) {
    throw PlantError(where + ": fmi2GetTypesPlatform returned \"" +
                     (platform != nullptr ? platform : "(null)") +
                     "\", not \"default\": " + "hiltwin passes the standard's default types");
  }
}

FmuLibrary::~FmuLibrary() {
  if (handle_ != nullptr) {
    dlclose(handle_);
  }
}

}  // namespace hiltwin::fmi
