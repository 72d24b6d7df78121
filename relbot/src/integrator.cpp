#include "hiltwin/relbot/integrator.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {

Integrator ParseIntegrator(std::string_view name) {
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (lower == "euler") return Integrator::kEuler;
  if (lower == "rk2") return Integrator::kRk2;
  if (lower == "rk4") return Integrator::kRk4;
  throw ConfigError("unknown integrator '" + std::string(name) +
                    "'; choose one of euler, rk2, rk4 (rk4 is the default and the most "
                    "accurate, thesis §3.8.1)");
}

std::string_view IntegratorName(Integrator integrator) noexcept {
  switch (integrator) {
    case Integrator::kEuler:
      return "euler";
    case Integrator::kRk2:
      return "rk2";
    case Integrator::kRk4:
      return "rk4";
  }
  return "rk4";
}

std::complex<double> StabilityFunction(Integrator integrator, std::complex<double> z) noexcept {
  switch (integrator) {
    case Integrator::kEuler:
      return 1.0 + z;
    case Integrator::kRk2:
      return 1.0 + z + z * z / 2.0;
    case Integrator::kRk4:
      return 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0;
  }
  return 1.0 + z;
}

namespace {

constexpr double kMaxStepS = 1.0;

bool StableAt(Integrator integrator, std::complex<double> mode, double step_s) noexcept {
  return std::abs(StabilityFunction(integrator, step_s * mode)) <= 1.0 + 1e-12;
}

// The stable steps of one decaying mode form an interval [0, h*] for these methods along
// any ray into the left half-plane: scan up geometrically to the first unstable step, then
// bisect the last stable one.
double MaxStableStepOfMode(Integrator integrator, std::complex<double> mode) noexcept {
  double stable_s = 0.0;
  double step_s = 1e-7;
  while (step_s <= kMaxStepS && StableAt(integrator, mode, step_s)) {
    stable_s = step_s;
    step_s *= 1.1;
  }
  if (step_s > kMaxStepS) return kMaxStepS;
  double unstable_s = step_s;
  for (int i = 0; i < 60; ++i) {
    const double mid_s = 0.5 * (stable_s + unstable_s);
    (StableAt(integrator, mode, mid_s) ? stable_s : unstable_s) = mid_s;
  }
  return stable_s;
}

}  // namespace

double MaxStableStepS(Integrator integrator, std::span<const std::complex<double>> modes) noexcept {
  double max_step_s = kMaxStepS;
  for (const std::complex<double> mode : modes) {
    if (std::abs(mode) < 1e-6) continue;
    max_step_s = std::min(max_step_s, MaxStableStepOfMode(integrator, mode));
  }
  return max_step_s;
}

}  // namespace hiltwin::app
