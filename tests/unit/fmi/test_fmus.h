#pragma once
// Paths of the FMUs tests/fmus builds, and the analytic answers of the two good ones.

#include <cmath>
#include <filesystem>
#include <string>

#include "fakes/test_paths.h"

namespace hiltwin::fmi::test {

inline std::filesystem::path TestFmu(const std::string& name) {
  return std::filesystem::path(HILTWIN_TEST_FMU_DIR) / (name + ".fmu");
}

// lag.fmu's parameters (lag.xml.in) and its answer from y = 0 with u held.
constexpr double kLagGain = 2.0;
constexpr double kLagTauS = 0.5;
inline double LagY(double u, double t_s) {
  return kLagGain * u * (1.0 - std::exp(-t_s / kLagTauS));
}

// msd.fmu's parameters (msd.xml.in) and the closed-form under-damped response from x0, v = 0.
constexpr double kMsdMassKg = 1.0;
constexpr double kMsdSpringNPerM = 40.0;
constexpr double kMsdDampingNsPerM = 0.8;
constexpr double kMsdX0M = 0.1;
struct MsdState {
  double x_m;
  double v_m_per_s;
};
inline MsdState MsdResponse(double force_n, double t_s) {
  const double wn = std::sqrt(kMsdSpringNPerM / kMsdMassKg);
  const double sigma = kMsdDampingNsPerM / (2.0 * kMsdMassKg);
  const double wd = std::sqrt(wn * wn - sigma * sigma);
  const double x_eq = force_n / kMsdSpringNPerM;
  const double e0 = kMsdX0M - x_eq;
  const double decay = std::exp(-sigma * t_s);
  const double c = std::cos(wd * t_s);
  const double s = std::sin(wd * t_s);
  return {x_eq + decay * (e0 * c + sigma * e0 / wd * s), decay * (-wn * wn * e0 / wd * s)};
}

}  // namespace hiltwin::fmi::test
