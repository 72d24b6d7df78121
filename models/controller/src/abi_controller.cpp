// The loader of C ABI controllers (abi_controller.h): dlopen, the descriptor's checks, and the
// Controller that calls its entry points.
#include "hiltwin/controller/abi_controller.h"

#include <dlfcn.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "elf_header.h"
#include "hiltwin/controller/content_hash.h"
#include "hiltwin/controller_abi.h"
#include "hiltwin/plant/twentysim_plant.h"  // FormatNumber, RateForStep: the same --rate advice

namespace hiltwin::controller {
namespace {

using plant::twentysim_detail::FormatNumber;

/// More ports than any controller has: a count beyond it is a descriptor that is not one.
constexpr std::uint32_t kMaxPorts = 1024;

constexpr const char* kAbiHeaderAdvice =
    "rebuild the library against the installed hiltwin/controller_abi.h "
    "(docs/controller-abi.md)";

/// What Step reports when step() failed and the library has no text for it.
constexpr const char* kStepFailedNoText =
    "the controller's step() returned nonzero and it has no last_error text";

/// The dlopen handle, closed when the controller goes.
class Library {
 public:
  Library() = default;
  explicit Library(void* handle) noexcept : handle_(handle) {}
  ~Library() {
    if (handle_ != nullptr) dlclose(handle_);
  }
  Library(Library&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
  Library& operator=(Library&&) = delete;
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;
  [[nodiscard]] void* get() const noexcept { return handle_; }

 private:
  void* handle_ = nullptr;
};

/// What every message starts with: the spec as typed, and the file when it differs.
std::string Where(const std::string& path, const std::filesystem::path& absolute) {
  std::string where = "controller lib:" + path;
  if (absolute.string() != path) where += " (" + absolute.string() + ")";
  return where;
}

Library Open(const std::string& where, const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    throw ControllerError(where + ": no such file: build the controller first (docs/" +
                          "controller-abi.md), or give the path of its .so after lib:");
  }
  if (!std::filesystem::is_regular_file(file, error)) {
    throw ControllerError(where + ": not a regular file: give the path of the controller's .so");
  }
  dlerror();  // NOLINT(concurrency-mt-unsafe): clear a stale error; per thread in glibc
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = dlerror();  // NOLINT(concurrency-mt-unsafe): per thread in glibc
    std::string advice = ExplainUnloadableElf(file);
    if (advice.empty()) {
      advice = "it must be a shared library built for this machine's architecture whose own "
               "dependencies are installed (file, ldd)";
    }
    throw ControllerError(where + ": cannot be loaded (" +
                          (why != nullptr ? why : "dlopen failed") + "): " + advice);
  }
  return Library(handle);
}

const hiltwin_controller_descriptor& Describe(const std::string& where, const Library& library) {
  dlerror();  // NOLINT(concurrency-mt-unsafe): clear a stale error; per thread in glibc
  void* address = dlsym(library.get(), HILTWIN_CONTROLLER_ENTRY);
  if (address == nullptr) {
    throw ControllerError(
        where + ": the library does not export the symbol " HILTWIN_CONTROLLER_ENTRY
                ": define `const hiltwin_controller_descriptor* " HILTWIN_CONTROLLER_ENTRY
                "(void)` with external linkage (extern \"C\" in C++) after including "
                "hiltwin/controller_abi.h, which exports it; `nm -D --defined-only` on the "
                "file lists what it exports");
  }
  // dlsym returns object pointers; POSIX guarantees the function pointer conversion.
  const auto entry = reinterpret_cast<hiltwin_controller_fn>(address);
  const hiltwin_controller_descriptor* descriptor = entry();
  if (descriptor == nullptr) {
    throw ControllerError(where + ": " HILTWIN_CONTROLLER_ENTRY "() returned NULL: return the "
                                  "address of a static const hiltwin_controller_descriptor");
  }
  return *descriptor;
}

void CheckVersion(const std::string& where, const hiltwin_controller_descriptor& d) {
  if (d.abi_version == HILTWIN_CONTROLLER_ABI_VERSION) return;
  throw ControllerError(where + ": built against controller ABI version " +
                        std::to_string(d.abi_version) + ", but this hiltwin speaks version " +
                        std::to_string(HILTWIN_CONTROLLER_ABI_VERSION) + ": " +
                        kAbiHeaderAdvice);
}

void CheckEntryPoints(const std::string& where, const hiltwin_controller_descriptor& d) {
  const std::pair<const char*, bool> required[] = {
      {"create", d.create != nullptr}, {"start", d.start != nullptr},
      {"step", d.step != nullptr},     {"finish", d.finish != nullptr},
      {"destroy", d.destroy != nullptr}};
  for (const auto& [name, present] : required) {
    if (present) continue;
    throw ControllerError(where + ": the descriptor's entry point " + name +
                          " is NULL: every entry point but last_error is required; point " +
                          name + " at a function (an empty one if there is nothing to do)");
  }
}

bool IsPortName(std::string_view name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                    (c >= '0' && c <= '9') || c == '_';
    if (!ok) return false;
  }
  return true;
}

std::vector<Port> ReadPorts(const std::string& where, const char* side,
                            const hiltwin_port* ports, std::uint32_t count) {
  const std::string list = std::string(side) + "s";
  if (count > kMaxPorts) {
    throw ControllerError(where + ": " + std::to_string(count) + " " + list + " (more than " +
                          std::to_string(kMaxPorts) + "): set " + side + "_count to the " +
                          "length of the " + list + " array");
  }
  if (count > 0 && ports == nullptr) {
    throw ControllerError(where + ": " + side + "_count is " + std::to_string(count) +
                          " but " + list + " is NULL: point it at the port array");
  }
  // "<where>: inputs[3]", built only for a message.
  const auto at = [&](std::uint32_t i) {
    std::string text = where;
    text.append(": ").append(list).append("[").append(std::to_string(i)).append("]");
    return text;
  };
  std::vector<Port> out;
  std::set<std::string, std::less<>> seen;
  for (std::uint32_t i = 0; i < count; ++i) {
    const char* name = ports[i].name;
    if (name == nullptr || !IsPortName(name)) {
      const std::string what =
          name == nullptr ? std::string("a NULL name") : "the name \"" + std::string(name) + "\"";
      throw ControllerError(at(i) + " has " + what +
                            ": a port name is letters, digits and '_', such as wheel_left_m");
    }
    if (ports[i].unit == nullptr) {
      throw ControllerError(at(i) + " (" + name + ") has a NULL unit: give its unit (\"m\", " +
                            "\"rad\", \"1\" for a duty...) or \"\" when it has none");
    }
    if (!seen.insert(name).second) {
      throw ControllerError(at(i) + ": the " + side + " " + name + " is listed twice: give " +
                            "every " + side + " its own name");
    }
    out.push_back(Port{name, ports[i].unit});
  }
  return out;
}

void CheckStepAndName(const std::string& where, const hiltwin_controller_descriptor& d) {
  if (d.name == nullptr || *d.name == '\0') {
    throw ControllerError(where + ": the descriptor's name is " +
                          (d.name == nullptr ? "NULL" : "empty") +
                          ": name the controller (the run report shows it)");
  }
  if (!std::isfinite(d.step_s) || d.step_s < 0.0) {
    throw ControllerError(where + ": the descriptor's step_s is " + FormatNumber(d.step_s, 9) +
                          ": give the step it was written for in seconds, or 0 for any step");
  }
  if (d.output_count == 0) {
    throw ControllerError(where + ": the controller has no outputs: list its outputs (such as " +
                          "duty_left, duty_right) in the descriptor");
  }
}

std::string DescribeStep(double step_s) {
  if (step_s > 0.0) return FormatNumber(step_s, 9) + " s (fixed)";
  return "any (start() is given the run's)";
}

class AbiController final : public Controller {
 public:
  AbiController(std::string where, Library library, const hiltwin_controller_descriptor& d,
                ControllerInfo info)
      : where_(std::move(where)), library_(std::move(library)), d_(d), info_(std::move(info)) {}
  ~AbiController() override { AbiController::Finish(); }
  AbiController(const AbiController&) = delete;
  AbiController& operator=(const AbiController&) = delete;
  AbiController(AbiController&&) = delete;
  AbiController& operator=(AbiController&&) = delete;

  [[nodiscard]] const ControllerInfo& Info() const noexcept override { return info_; }
  void Start(double step_s) override;
  [[nodiscard]] ControllerStatus Step(std::span<const double> in,
                                      std::span<double> out) noexcept override;
  void Finish() noexcept override;

 private:
  void CheckStep(double step_s) const;
  [[nodiscard]] const char* LastError() const noexcept;

  std::string where_;
  Library library_;  // before the state: the code that frees it is in the library
  hiltwin_controller_descriptor d_;
  ControllerInfo info_;
  void* self_ = nullptr;
  bool started_ = false;
  std::array<char, 256> step_error_{};  ///< the last step error's text (longer text is cut)
};

void AbiController::CheckStep(double step_s) const {
  const double fixed_s = info_.model_step_s;
  if (!std::isfinite(step_s) || step_s <= 0.0) {
    throw ControllerError(where_ + ": cannot run at a step of " + FormatNumber(step_s, 9) +
                          " s: give --rate in Hz, greater than 0");
  }
  if (!info_.step_is_fixed || std::abs(step_s - fixed_s) <= plant::kTwentySimStepToleranceS) {
    return;
  }
  throw ControllerError(where_ + ": --rate " + FormatNumber(1.0 / step_s, 6) +
                        " Hz gives a step of " + FormatNumber(step_s, 9) + " s but '" +
                        info_.name + "' was written for a step of " + FormatNumber(fixed_s, 9) +
                        " s (its descriptor's step_s): run at --rate " +
                        plant::twentysim_detail::RateForStep(fixed_s) +
                        ", or set step_s to 0 to take any step");
}

void AbiController::Start(double step_s) {
  CheckStep(step_s);
  Finish();  // a second Start begins from a fresh state
  self_ = d_.create();
  if (self_ == nullptr) {
    throw ControllerError(where_ + ": its create() returned NULL, so '" + info_.name +
                          "' has no state to run: check what create() allocates or refuses");
  }
  const int code = d_.start(self_, step_s);
  if (code != 0) {
    const std::string why = LastError() != nullptr ? LastError() : "no last_error text";
    d_.destroy(self_);
    self_ = nullptr;
    throw ControllerError(where_ + ": its start(step_s = " + FormatNumber(step_s, 9) +
                          ") returned " + std::to_string(code) + ": " + why +
                          "; the run did not start");
  }
  started_ = true;
}

ControllerStatus AbiController::Step(std::span<const double> in,
                                     std::span<double> out) noexcept {
  if (!started_) return ControllerStatus::Error("the controller was not started");
  if (in.size() != d_.input_count || out.size() != d_.output_count) {
    return ControllerStatus::Error("the controller was given the wrong number of values");
  }
  if (d_.step(self_, in.data(), out.data()) == 0) return ControllerStatus::Ok();
  const char* why = LastError();
  if (why == nullptr || *why == '\0') return ControllerStatus::Error(kStepFailedNoText);
  // The library's text lives until its next call, or its destroy(): a copy in a buffer of our
  // own (a bounded copy, no allocation) stays valid until this controller goes, so the report
  // can name it after Finish.
  const std::size_t length = strnlen(why, step_error_.size() - 1);
  std::memcpy(step_error_.data(), why, length);
  step_error_[length] = '\0';
  return ControllerStatus::Error(step_error_.data());
}

const char* AbiController::LastError() const noexcept {
  if (d_.last_error == nullptr || self_ == nullptr) return nullptr;
  return d_.last_error(self_);
}

void AbiController::Finish() noexcept {
  if (self_ == nullptr) return;
  if (started_) d_.finish(self_);
  d_.destroy(self_);
  self_ = nullptr;
  started_ = false;
}

ControllerInfo MakeInfo(const std::string& path, const std::filesystem::path& file,
                        const std::string& where, const hiltwin_controller_descriptor& d) {
  ControllerInfo info;
  info.spec = "lib:" + path;
  info.kind = kAbiControllerKind;
  info.name = d.name;
  info.file = file.string();
  info.content_sha256 = Sha256HexOfFile(file);
  info.inputs = ReadPorts(where, "input", d.inputs, d.input_count);
  info.outputs = ReadPorts(where, "output", d.outputs, d.output_count);
  info.model_step_s = d.step_s;
  info.step_is_fixed = d.step_s > 0.0;
  info.details = {{"ABI version", std::to_string(d.abi_version)},
                  {"step", DescribeStep(d.step_s)}};
  return info;
}

}  // namespace

std::unique_ptr<Controller> LoadAbiController(const std::string& path) {
  const std::filesystem::path file = std::filesystem::absolute(path).lexically_normal();
  const std::string where = Where(path, file);
  Library library = Open(where, file);
  const hiltwin_controller_descriptor& d = Describe(where, library);
  CheckVersion(where, d);  // first: another version's descriptor may have another layout
  CheckEntryPoints(where, d);
  CheckStepAndName(where, d);
  ControllerInfo info = MakeInfo(path, file, where, d);
  return std::make_unique<AbiController>(where, std::move(library), d, std::move(info));
}

}  // namespace hiltwin::controller
