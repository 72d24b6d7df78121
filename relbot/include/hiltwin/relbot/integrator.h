#pragma once
/// Fixed-step explicit integrators as 20-sim offers them (thesis §3.8.1): Euler, Runge-Kutta 2
/// (midpoint) and Runge-Kutta 4. Generic over a fixed-size Eigen state and a derivative
/// functor `f(const State& x, State& dxdt) noexcept`; the stages live on the stack, so a step
/// allocates nothing.

#include <complex>
#include <span>
#include <string_view>

namespace hiltwin::app {

/// Explicit integration method; kRk4 is the default (thesis §3.8.1).
enum class Integrator { kEuler, kRk2, kRk4 };

/// "euler", "rk2" or "rk4" (case-insensitive); throws ConfigError listing the choices.
[[nodiscard]] Integrator ParseIntegrator(std::string_view name);

/// The name ParseIntegrator accepts for `integrator`.
[[nodiscard]] std::string_view IntegratorName(Integrator integrator) noexcept;

/// Derivative evaluations per step (1, 2 or 4): what a step costs.
[[nodiscard]] constexpr int StagesPerStep(Integrator integrator) noexcept {
  return integrator == Integrator::kEuler ? 1 : integrator == Integrator::kRk2 ? 2 : 4;
}

/// The method's stability function R(z): one step maps x' = λx to x·R(hλ) with z = hλ
/// (1 + z for Euler; the truncated exponential series to order 2 and 4 for RK2 and RK4).
[[nodiscard]] std::complex<double> StabilityFunction(Integrator integrator,
                                                     std::complex<double> z) noexcept;

/// Largest step in seconds at which `integrator` keeps every mode with eigenvalue `modes`
/// (1/s) from growing: |R(h·λ)| <= 1 for all of them. Modes with |λ| below 1e-6 1/s (pure
/// integrators, such as positions) are marginal at any step and ignored. At most 1 s.
[[nodiscard]] double MaxStableStepS(Integrator integrator,
                                    std::span<const std::complex<double>> modes) noexcept;

/// x(t+h) = x + h f(x).
template <class State, class Derivative>
inline void EulerStep(const Derivative& f, State& x, double h) noexcept {
  State k1;
  f(x, k1);
  x += h * k1;
}

/// Midpoint rule: x(t+h) = x + h f(x + h/2 f(x)). Second order.
template <class State, class Derivative>
inline void Rk2Step(const Derivative& f, State& x, double h) noexcept {
  State k1;
  State k2;
  f(x, k1);
  const State mid = x + (0.5 * h) * k1;
  f(mid, k2);
  x += h * k2;
}

/// Classical fourth-order Runge-Kutta.
template <class State, class Derivative>
inline void Rk4Step(const Derivative& f, State& x, double h) noexcept {
  State k1;
  State k2;
  State k3;
  State k4;
  State tmp;
  f(x, k1);
  tmp = x + (0.5 * h) * k1;
  f(tmp, k2);
  tmp = x + (0.5 * h) * k2;
  f(tmp, k3);
  tmp = x + h * k3;
  f(tmp, k4);
  x += (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

/// One step with the chosen method.
template <class State, class Derivative>
inline void IntegrateStep(Integrator method, const Derivative& f, State& x, double h) noexcept {
  switch (method) {
    case Integrator::kEuler:
      EulerStep(f, x, h);
      return;
    case Integrator::kRk2:
      Rk2Step(f, x, h);
      return;
    case Integrator::kRk4:
      Rk4Step(f, x, h);
      return;
  }
}

}  // namespace hiltwin::app
