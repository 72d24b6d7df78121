// FmuPlant: the FMI 2.0 co-simulation calling sequence behind the plant interface.
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>

#include "fmu_plant_impl.h"

namespace hiltwin::fmi {
namespace {

using plant::PlantError;
using plant::PlantStatus;

// Static text per call and status: Step cannot build strings.
#define HILTWIN_FMI_STEP_REASONS(call)                                                        \
  {                                                                                           \
    call " returned fmi2OK", call " returned fmi2Warning", call " returned fmi2Discard",      \
        call " returned fmi2Error", call " returned fmi2Fatal", call " returned fmi2Pending", \
        call " returned an unknown fmi2Status"                                                \
  }
constexpr const char* kSetRealReasons[] = HILTWIN_FMI_STEP_REASONS("fmi2SetReal");
constexpr const char* kDoStepReasons[] = HILTWIN_FMI_STEP_REASONS("fmi2DoStep");
constexpr const char* kGetRealReasons[] = HILTWIN_FMI_STEP_REASONS("fmi2GetReal");
#undef HILTWIN_FMI_STEP_REASONS

const char* StepFaultReason(StepCall call, fmi2Status status) noexcept {
  const int raw = static_cast<int>(status);
  const std::size_t index = raw >= 0 && raw <= 5 ? static_cast<std::size_t>(raw) : 6U;
  switch (call) {
    case StepCall::kSetReal:
      return kSetRealReasons[index];
    case StepCall::kDoStep:
      return kDoStepReasons[index];
    case StepCall::kGetReal:
      return kGetRealReasons[index];
  }
  return "an FMU call failed";
}

bool Succeeded(fmi2Status status) noexcept { return status == fmi2OK || status == fmi2Warning; }

// RFC 3986 file URI of a local folder (FMI 2.0 §2.1.5: fmuResourceLocation is a URI).
std::string FileUri(const std::filesystem::path& dir) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string uri = "file://";
  for (const char c : dir.string()) {
    const auto byte = static_cast<unsigned char>(c);
    if (std::isalnum(byte) != 0 || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') {
      uri += c;
    } else {
      uri += '%';
      uri += kHex[byte >> 4U];
      uri += kHex[byte & 0xFU];
    }
  }
  return uri;
}

// "an Integer", "a parameter": the article a word takes (by its first letter).
std::string WithArticle(std::string_view word) {
  const bool vowel = !word.empty() && std::string_view("aeiouAEIOU").find(word.front()) !=
                                          std::string_view::npos;
  return (vowel ? "an " : "a ") + std::string(word);
}

// What a variable of a causality FMI 2.0 names (§2.2.7) is, as a noun for messages.
std::string CausalityNoun(const std::string& causality) {
  if (causality == "parameter") return "a parameter";
  if (causality == "calculatedParameter") return "a calculated parameter";
  if (causality == "local") return "a local variable";
  if (causality == "independent") return "the independent variable";
  return WithArticle(causality) + " variable";
}

}  // namespace

FmuPlantImpl::FmuPlantImpl(const std::filesystem::path& fmu_path, FmuOptions options)
    : fmu_name_(fmu_path.string()),
      unpacked_(fmu_path, options.unpack_limits),
      md_(ReadModelDescription(unpacked_.dir() / "modelDescription.xml", fmu_name_)),
      library_(unpacked_, md_.model_identifier, fmu_name_),
      fn_(library_.functions()),
      debug_logging_(options.debug_logging),
      log_(md_.model_identifier, options.log_capacity_messages, std::move(options.log_sink)),
      callbacks_{&FmuLog::Callback, &std::calloc, &std::free, nullptr, &log_},
      resource_uri_(FileUri(unpacked_.dir() / "resources")) {
  info_.name = "fmu:" + fmu_name_;
  info_.kind = "FMI 2.0 co-simulation";
  info_.model_step_s = md_.default_step_s.value_or(0.0);
  info_.step_is_fixed = false;
  info_.details = {{"modelName", md_.model_name},
                   {"modelIdentifier", md_.model_identifier},
                   {"generationTool", md_.generation_tool},
                   {"guid", md_.guid},
                   {"fmiVersion", md_.fmi_version}};
  BuildPorts();
}

FmuPlantImpl::~FmuPlantImpl() { Finish(); }

void FmuPlantImpl::BuildPorts() {
  for (const ScalarVariable& variable : md_.variables) {
    if (variable.type != "Real") {
      continue;
    }
    if (variable.causality == "input") {
      info_.inputs.push_back({variable.name, variable.unit});
      input_refs_.push_back(variable.value_reference);
    } else if (variable.causality == "output") {
      info_.outputs.push_back({variable.name, variable.unit});
      output_refs_.push_back(variable.value_reference);
    }
  }
  initial_inputs_.assign(input_refs_.size(), 0.0);
  step_inputs_ = input_refs_;  // the vectors do not change after this: their views stay valid
  step_outputs_ = output_refs_;
}

void FmuPlantImpl::SetInitialInputs(std::span<const double> u0) {
  if (u0.size() != initial_inputs_.size()) {
    throw PlantError("SetInitialInputs of " + info_.name + " was given " +
                     std::to_string(u0.size()) + " values for its " +
                     std::to_string(initial_inputs_.size()) + " inputs (a bug in the caller)");
  }
  initial_inputs_.assign(u0.begin(), u0.end());
}

void FmuPlantImpl::Check(fmi2Status status, const char* call) {
  if (Succeeded(status)) {
    return;
  }
  worst_ = status;
  log_.Drain();  // the FMU's own account comes out before the error that ends the command
  throw PlantError(fmu_name_ + ": " + call + " returned " + StatusName(status) +
                   " while starting the FMU (its log, if it wrote one, is above): check the " +
                   "FMU's parameters in the exporting tool, or report it to the tool's makers");
}

void FmuPlantImpl::CheckOutputSpan(std::span<double> y0, const char* call) const {
  if (y0.size() != output_refs_.size()) {
    throw PlantError(std::string(call) + " of " + info_.name + " was given " +
                     std::to_string(y0.size()) + " output values for its " +
                     std::to_string(output_refs_.size()) + " outputs (a bug in the caller)");
  }
}

void FmuPlantImpl::Instantiate() {
  component_ = fn_.instantiate(md_.model_identifier.c_str(), fmi2CoSimulation, md_.guid.c_str(),
                               resource_uri_.c_str(), &callbacks_, fmi2False,
                               debug_logging_ ? fmi2True : fmi2False);
  if (component_ == nullptr) {
    log_.Drain();
    throw PlantError(fmu_name_ + ": fmi2Instantiate failed (returned NULL; its log, if it " +
                     "wrote one, is above): the binary may not match the model description's " +
                     "guid " + md_.guid + ": export the FMU again");
  }
  initialised_ = false;
  ready_ = false;
  worst_ = fmi2OK;
}

void FmuPlantImpl::Initialise(std::span<double> y0) {
  status_ = PlantStatus::Ok();
  steps_ = 0;
  Check(fn_.setup_experiment(component_, fmi2False, 0.0, 0.0, fmi2False, 0.0),
        "fmi2SetupExperiment");
  Check(fn_.enter_initialization_mode(component_), "fmi2EnterInitializationMode");
  // The inputs held until the first step (the map's constants, 0 for the PWM-driven ones), so
  // the initial outputs are the ones the first step continues from.
  if (!input_refs_.empty()) {
    Check(fn_.set_real(component_, input_refs_.data(), input_refs_.size(),
                       initial_inputs_.data()),
          "fmi2SetReal");
  }
  Check(fn_.exit_initialization_mode(component_), "fmi2ExitInitializationMode");
  initialised_ = true;
  ready_ = true;
  if (!output_refs_.empty()) {
    Check(fn_.get_real(component_, output_refs_.data(), output_refs_.size(), y0.data()),
          "fmi2GetReal");
  }
}

void FmuPlantImpl::Start(double step_s, std::span<double> y0) {
  if (!(step_s > 0.0) || !std::isfinite(step_s)) {
    throw plant::PlantStepError(info_.name + ": the step must be a positive number of seconds, "
                                "not " + std::to_string(step_s));
  }
  CheckOutputSpan(y0, "Start");
  Finish();  // a second Start begins with a fresh instance
  step_s_ = step_s;
  Instantiate();
  Initialise(y0);
  log_.Drain();
}

void FmuPlantImpl::Reset(std::span<double> y0) {
  CheckOutputSpan(y0, "Reset");
  if (component_ == nullptr) {
    throw PlantError(info_.name + ": Reset before Start (a bug in the caller)");
  }
  if (worst_ == fmi2Fatal) {
    throw PlantError(fmu_name_ + ": the FMU returned fmi2Fatal, after which FMI 2.0 allows " +
                     "no further call to it: open the FMU again");
  }
  initialised_ = false;
  ready_ = false;
  Check(fn_.reset(component_), "fmi2Reset");
  worst_ = fmi2OK;
  Initialise(y0);
  log_.Drain();
}

PlantStatus FmuPlantImpl::Latch(StepCall call, fmi2Status status) noexcept {
  worst_ = status;
  ready_ = false;
  status_ = PlantStatus::Fault(StepFaultReason(call, status));
  return status_;
}

PlantStatus FmuPlantImpl::Refuse() noexcept {
  if (status_.ok()) {  // otherwise the fault stays: FMI 2.0 allows no further doStep after one
    ready_ = false;
    status_ = PlantStatus::Fault("FMU plant stepped before Start or with the wrong port count");
  }
  return status_;
}

// The per-step path: one flag for "started, initialised, not faulted" and the port counts
// checked against views fixed at construction; the FMU's three calls take their arguments from
// locals, so nothing is reloaded after a call.
PlantStatus FmuPlantImpl::Step(std::span<const double> u, std::span<double> y) noexcept {
  if (!ready_ || u.size() != step_inputs_.size() || y.size() != step_outputs_.size())
      [[unlikely]] {
    return Refuse();
  }
  const fmi2Component component = component_;
  fmi2Status status = fmi2OK;
  if (!step_inputs_.empty()) {
    status = fn_.set_real(component, step_inputs_.data(), step_inputs_.size(), u.data());
    if (!Succeeded(status)) [[unlikely]] {
      return Latch(StepCall::kSetReal, status);
    }
  }
  // Model time k h, never accumulated; steps_ < 2^63, so the signed conversion is the same.
  const double t_s = static_cast<double>(static_cast<std::int64_t>(steps_)) * step_s_;
  status = fn_.do_step(component, t_s, step_s_, fmi2True);
  if (!Succeeded(status)) [[unlikely]] {
    return Latch(StepCall::kDoStep, status);
  }
  ++steps_;
  if (!step_outputs_.empty()) {
    status = fn_.get_real(component, step_outputs_.data(), step_outputs_.size(), y.data());
    if (!Succeeded(status)) [[unlikely]] {
      return Latch(StepCall::kGetReal, status);
    }
  }
  return PlantStatus::Ok();
}

void FmuPlantImpl::Finish() noexcept {
  if (component_ != nullptr) {
    // FMI 2.0's state machine: after fmi2Error only fmi2FreeInstance (or fmi2Reset) is
    // allowed; after fmi2Fatal nothing, so the instance is abandoned.
    if (worst_ != fmi2Fatal) {
      if (initialised_ && worst_ != fmi2Error) {
        static_cast<void>(fn_.terminate(component_));
      }
      fn_.free_instance(component_);
    }
    component_ = nullptr;
    initialised_ = false;
    ready_ = false;
  }
  try {
    log_.Drain();
  } catch (...) {  // a sink that throws cannot be reported from here
  }
}

std::string FmuPlantImpl::ExplainNonPort(std::string_view name) const {
  const ScalarVariable* variable = md_.Find(name);
  if (variable == nullptr) {
    return {};
  }
  const std::string file = std::filesystem::path(fmu_name_).filename().string();
  if (variable->type != "Real") {
    return "is " + WithArticle(variable->type) + " variable of " + file +
           "; only Real ports can be mapped";
  }
  if (variable->causality == "input" || variable->causality == "output") {
    return {};
  }
  return "is " + CausalityNoun(variable->causality) + " of " + file + " (causality \"" +
         variable->causality + "\"); only inputs can be driven and outputs followed";
}

FmuDirectCalls FmuPlantImpl::DirectCalls() const noexcept {
  return {component_, fn_.set_real, fn_.do_step, fn_.get_real, input_refs_, output_refs_};
}

std::unique_ptr<FmuPlant> OpenFmu(const std::filesystem::path& fmu_path, FmuOptions options) {
  return std::make_unique<FmuPlantImpl>(fmu_path, std::move(options));
}

std::unique_ptr<plant::Plant> OpenFmuPlant(const std::filesystem::path& fmu_path,
                                           const plant::PlantOptions& options) {
  if (!options.config_path.empty()) {
    throw PlantError("--config " + options.config_path + " cannot apply to fmu:" +
                     fmu_path.string() + ": an FMU brings its own parameters, set in the tool " +
                     "that exported it: drop --config, or export the FMU with the values you want");
  }
  if (!options.integrator.empty()) {
    throw PlantError("--integrator " + options.integrator + " cannot apply to fmu:" +
                     fmu_path.string() + ": a co-simulation FMU brings its own solver, chosen " +
                     "in the tool that exported it: drop --integrator");
  }
  return OpenFmu(fmu_path);
}

}  // namespace hiltwin::fmi
