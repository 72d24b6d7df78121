#pragma once
// A plant whose answer a test can compute by hand: each output is its input times a gain plus
// the step count (y[i] = gain * u[i % inputs] + steps * slope), so the twin task's routing,
// scaling and time are visible in every value.

#include <cmath>
#include <limits>

#include "hiltwin/plant/plant.h"

namespace hiltwin::plant::test {

class FakePlant final : public Plant {
 public:
  FakePlant(std::vector<Port> inputs, std::vector<Port> outputs) {
    info_.name = "fake";
    info_.kind = "test";
    info_.inputs = std::move(inputs);
    info_.outputs = std::move(outputs);
  }
  [[nodiscard]] const PlantInfo& Info() const noexcept override { return info_; }
  void Start(double step_s, std::span<double> y0) override {
    step_s_ = step_s;
    steps_ = 0;
    for (std::size_t i = 0; i < y0.size(); ++i) y0[i] = initial;
  }
  [[nodiscard]] PlantStatus Step(std::span<const double> u, std::span<double> y) noexcept override {
    ++steps_;
    if (steps_ == fault_at) return PlantStatus::Fault("the fake plant failed");
    if (steps_ == finish_at) return PlantStatus::Finished("the fake plant finished");
    for (std::size_t i = 0; i < y.size(); ++i) {
      y[i] = initial + gain * u[i % u.size()] + slope * static_cast<double>(steps_);
    }
    if (steps_ == nan_at) y[nan_index] = nan_value;
    return PlantStatus::Ok();
  }
  void Reset(std::span<double> y0) override { Start(step_s_, y0); }
  [[nodiscard]] std::string ExplainNonPort(std::string_view name) const override {
    return name == "k" ? "is a parameter of the fake plant" : "";
  }

  double initial = 0.0;
  double gain = 1.0;
  double slope = 0.0;
  std::uint64_t fault_at = 0;  ///< 0: never
  std::uint64_t finish_at = 0;
  std::uint64_t nan_at = 0;
  std::size_t nan_index = 0;  ///< the output nan_at overwrites, with nan_value
  double nan_value = std::numeric_limits<double>::quiet_NaN();

 private:
  PlantInfo info_;
  double step_s_ = 0.0;
  std::uint64_t steps_ = 0;
};

}  // namespace hiltwin::plant::test
