#pragma once
// The FmuPlant behind OpenFmu: members in the order they must be built and torn down (the
// folder outlives the library loaded from it; the library outlives the instance).

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fmu_archive.h"
#include "fmu_library.h"
#include "fmu_log.h"
#include "hiltwin/fmi/fmu_plant.h"
#include "model_description.h"

namespace hiltwin::fmi {

/// The FMU calls Step makes, for its static fault reasons.
enum class StepCall : std::uint8_t { kSetReal, kDoStep, kGetReal };

class FmuPlantImpl final : public FmuPlant {
 public:
  FmuPlantImpl(const std::filesystem::path& fmu_path, FmuOptions options);
  ~FmuPlantImpl() override;
  FmuPlantImpl(const FmuPlantImpl&) = delete;
  FmuPlantImpl& operator=(const FmuPlantImpl&) = delete;

  [[nodiscard]] const plant::PlantInfo& Info() const noexcept override { return info_; }
  void SetInitialInputs(std::span<const double> u0) override;
  void Start(double step_s, std::span<double> y0) override;
  [[nodiscard]] plant::PlantStatus Step(std::span<const double> u,
                                        std::span<double> y) noexcept override;
  void Reset(std::span<double> y0) override;
  void Finish() noexcept override;
  [[nodiscard]] std::string ExplainNonPort(std::string_view name) const override;

  std::size_t DrainLog() override { return log_.Drain(); }
  [[nodiscard]] std::uint64_t log_messages_dropped() const noexcept override {
    return log_.dropped();
  }
  [[nodiscard]] const std::filesystem::path& unpack_dir() const noexcept override {
    return unpacked_.dir();
  }
  [[nodiscard]] FmuDirectCalls DirectCalls() const noexcept override;
  /// What the FMU says about itself, for the controller adapter's checks (fmu_controller.cpp).
  [[nodiscard]] const ModelDescription& model_description() const noexcept { return md_; }

 private:
  void BuildPorts();
  void Instantiate();
  void Initialise(std::span<double> y0);
  void Check(fmi2Status status, const char* call);
  void CheckOutputSpan(std::span<double> y0, const char* call) const;
  plant::PlantStatus Latch(StepCall call, fmi2Status status) noexcept;
  plant::PlantStatus Refuse() noexcept;

  std::string fmu_name_;  ///< the path as given, for messages
  UnpackedFmu unpacked_;
  ModelDescription md_;
  FmuLibrary library_;
  Fmi2Functions fn_;  ///< a copy next to the hot data, for Step
  bool debug_logging_ = false;
  FmuLog log_;
  fmi2CallbackFunctions callbacks_;  ///< alive until fmi2FreeInstance, as FMI 2.0.1 requires
  std::string resource_uri_;
  plant::PlantInfo info_;
  std::vector<fmi2ValueReference> input_refs_;
  std::vector<fmi2ValueReference> output_refs_;
  std::vector<fmi2Real> initial_inputs_;  ///< set in initialisation mode (SetInitialInputs)

  fmi2Component component_ = nullptr;
  bool initialised_ = false;   ///< fmi2ExitInitializationMode returned ok
  /// Step may call the FMU: an instance, initialised, not faulted (one test per step).
  bool ready_ = false;
  std::span<const fmi2ValueReference> step_inputs_{};   ///< input_refs_, for Step
  std::span<const fmi2ValueReference> step_outputs_{};  ///< output_refs_, for Step
  fmi2Status worst_ = fmi2OK;  ///< the last failing status: what FMI 2.0 still allows
  plant::PlantStatus status_;  ///< latched: after a fault the FMU is not called again
  double step_s_ = 0.0;
  std::uint64_t steps_ = 0;  ///< model time = steps_ * step_s_ (never accumulated)
};

}  // namespace hiltwin::fmi
