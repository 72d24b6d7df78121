#include "hiltwin/app_relbot/integrator.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "hiltwin/app_relbot/relbot_params.h"

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

}  // namespace hiltwin::app
