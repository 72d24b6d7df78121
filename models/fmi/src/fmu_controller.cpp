// FmuController: an FMU plant's calling sequence (FmuPlantImpl) behind the controller
// interface. The controller's inputs are the plant's u, its outputs the plant's y; the initial
// outputs of Start are not the controller's (a controller's first outputs come from its first
// step), so they go to a buffer of its own.
#include "hiltwin/fmi/fmu_controller.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fmu_plant_impl.h"
#include "hiltwin/controller/content_hash.h"

namespace hiltwin::fmi {
namespace {

using controller::ControllerError;
using controller::ControllerStatus;

// A controller drives duties: every output must be a Real it can step. The plant skips other
// types silently (they cannot be mapped); a controller output that is skipped would leave a
// motor without its command, so it is refused.
void CheckOutputs(const ModelDescription& md, const std::string& fmu_name) {
  bool any_real_output = false;
  for (const ScalarVariable& variable : md.variables) {
    if (variable.causality != "output") continue;
    if (variable.type != "Real") {
      throw ControllerError(fmu_name + ": modelDescription.xml:" + std::to_string(variable.line) +
                            ": the output '" + variable.name + "' is of type " + variable.type +
                            ": a controller's outputs are duties, Real only: export it as a " +
                            "Real, or give it causality \"local\" if it is not a command");
    }
    any_real_output = true;
  }
  if (!any_real_output) {
    throw ControllerError(fmu_name + ": the FMU has no Real variable of causality \"output\": a " +
                          "controller needs at least one (a duty): export its commands as " +
                          "outputs");
  }
}

class FmuController final : public controller::Controller {
 public:
  FmuController(const std::filesystem::path& fmu_path, FmuOptions options)
      : fmu_(Open(fmu_path, std::move(options))) {
    const ModelDescription& md = fmu_->model_description();
    CheckOutputs(md, fmu_path.string());
    const plant::PlantInfo& plant_info = fmu_->Info();
    info_.spec = "fmu:" + fmu_path.string();
    info_.kind = plant_info.kind;  // "FMI 2.0 co-simulation"
    info_.name = md.model_name;
    info_.file = std::filesystem::absolute(fmu_path).lexically_normal().string();
    info_.content_sha256 = controller::Sha256HexOfFile(fmu_path);
    info_.inputs = plant_info.inputs;
    info_.outputs = plant_info.outputs;
    info_.model_step_s = plant_info.model_step_s;
    info_.step_is_fixed = false;  // the FMU's own solver takes any communication step
    info_.details = plant_info.details;
    initial_outputs_.assign(info_.outputs.size(), 0.0);
  }

  ~FmuController() override = default;
  FmuController(const FmuController&) = delete;
  FmuController& operator=(const FmuController&) = delete;
  FmuController(FmuController&&) = delete;
  FmuController& operator=(FmuController&&) = delete;

  [[nodiscard]] const controller::ControllerInfo& Info() const noexcept override { return info_; }

  void Start(double step_s) override {
    try {
      fmu_->Start(step_s, initial_outputs_);
    } catch (const plant::PlantError& e) {
      throw ControllerError(e.what());
    }
  }

  [[nodiscard]] ControllerStatus Step(std::span<const double> in,
                                      std::span<double> out) noexcept override {
    const plant::PlantStatus status = fmu_->Step(in, out);
    // A plant's kFinished cannot happen (an FMU has no finish time here); any status but ok
    // carries the failing call's static text ("fmi2DoStep returned fmi2Error").
    return status.ok() ? ControllerStatus::Ok() : ControllerStatus::Error(status.reason);
  }

  void Finish() noexcept override { fmu_->Finish(); }

 private:
  static std::unique_ptr<FmuPlantImpl> Open(const std::filesystem::path& fmu_path,
                                            FmuOptions options) {
    try {
      return std::make_unique<FmuPlantImpl>(fmu_path, std::move(options));
    } catch (const plant::PlantError& e) {
      throw ControllerError(e.what());
    }
  }

  std::unique_ptr<FmuPlantImpl> fmu_;
  controller::ControllerInfo info_;
  std::vector<double> initial_outputs_;  ///< Start's outputs at t = 0; not the controller's
};

}  // namespace

std::unique_ptr<controller::Controller> OpenFmuController(
    const std::filesystem::path& fmu_path, const controller::ControllerOptions& options,
    FmuOptions fmu_options) {
  if (!options.gains_path.empty()) {
    throw ControllerError(
        "--gains " + options.gains_path + " cannot apply to fmu:" + fmu_path.string() +
        ": an FMU brings its own parameters, set in " +
        "the tool that exported it: drop --gains, or export the FMU with " + "the gains you want");
  }
  return std::make_unique<FmuController>(fmu_path, std::move(fmu_options));
}

void RegisterFmuControllerKind() {
  controller::RegisterControllerKind(
      {"fmu", "an FMI 2.0 co-simulation FMU (its Real inputs and outputs are the ports)",
       [](const std::string& path, const controller::ControllerOptions& options) {
         return OpenFmuController(path, options);
       }});
}

}  // namespace hiltwin::fmi
