// A first-order lag, y' = (u - y) / tau, run as a twin behind the emulated IcoBoard (`--io
// mock`): the board's PWM channel 1 is held at duty 0.5, the plant map routes it to u and y to
// encoder channel 1, and a RunSession runs 1000 cycles at 1 kHz on the virtual clock.
// Prints the run summary (ending in the verdict), then y and the encoder count after the run:
// y = 0.5 (1 - 0.99^1000) ~ 0.49998 m, 499 counts. Exit code: ExitCodeFor(report).
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_map.h"
#include "hiltwin/plant/plant_twin_task.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/run_session.h"

namespace {

using hiltwin::plant::PlantStatus;

constexpr double kRateHz = 1000.0;
constexpr std::int64_t kPeriodNs = 1'000'000;
constexpr std::uint64_t kCycles = 1000;

/// The plant: one input, one output, explicit Euler at the twin's step.
class LagPlant final : public hiltwin::plant::Plant {
 public:
  explicit LagPlant(double tau_s) : tau_s_(tau_s) {
    info_.name = "lag";
    info_.kind = "out-of-tree example";
    info_.inputs = {{"u", "m"}};
    info_.outputs = {{"y", "m"}};
  }
  const hiltwin::plant::PlantInfo& Info() const noexcept override { return info_; }
  void Start(double step_s, std::span<double> y0) override {
    step_s_ = step_s;
    Reset(y0);
  }
  PlantStatus Step(std::span<const double> u, std::span<double> y) noexcept override {
    y_ += step_s_ / tau_s_ * (u[0] - y_);
    y[0] = y_;
    return PlantStatus::Ok();
  }
  void Reset(std::span<double> y0) override {
    y_ = 0.0;
    y0[0] = y_;
  }

 private:
  hiltwin::plant::PlantInfo info_;
  double tau_s_;
  double step_s_ = 0.0;
  double y_ = 0.0;
};

/// What a controller would write on the PWM lines: channel 1 at half duty, the others off.
class HalfDutyOnChannel1 final : public hiltwin::io::PwmSignalSource {
 public:
  void DutyAt(std::int64_t, std::array<double, hiltwin::io::kChannels>& out) noexcept override {
    out = {0.5, 0.0, 0.0, 0.0};
  }
};

constexpr const char* kMap = R"(
[[pwm]]
channel = 1
input = "u"
[[encoder]]
channel = 1
output = "y"
unit = "m"
counts_per_unit = 1000
)";

hiltwin::runtime::SessionConfig VirtualRun() {
  hiltwin::runtime::SessionConfig config;
  config.task_name = "lag twin";
  config.io = "mock";
  config.clock = hiltwin::runtime::ClockKind::kVirtual;
  config.rate_hz = kRateHz;
  config.executive.period_ns = kPeriodNs;
  config.executive.max_cycles = kCycles;
  config.qos.rules = hiltwin::qos::DefaultRules();
  config.qos.planned_cycles = kCycles;
  return config;
}

}  // namespace

int main() {
  LagPlant plant(0.1);
  const double step_s = 1.0 / kRateHz;
  std::vector<double> y0(1);
  plant.Start(step_s, y0);
  auto map = hiltwin::plant::BindPlantMap(hiltwin::plant::ParsePlantMap(kMap, "lag map"), plant);

  HalfDutyOnChannel1 pwm;
  auto backend = hiltwin::io::OpenBackend("mock", {});
  backend->AttachPwmSource(&pwm);
  hiltwin::io::IcoBoardInverse board(backend->bus());
  const hiltwin::io::InitResult init = board.Init(kPeriodNs);
  if (!init.ok) {
    std::fprintf(stderr, "lag_twin: the emulated board did not start: %s\n",
                 init.message.c_str());
    return 5;
  }
  hiltwin::plant::PlantTwinTask task(board, plant, std::move(map), step_s, y0);

  hiltwin::runtime::RunSession session(VirtualRun(), task);
  const hiltwin::runtime::RunReport report = session.Run();
  std::printf("%s", hiltwin::runtime::FormatSummary(report).c_str());
  std::printf("lag_twin: y = %.6f m after %llu steps, encoder 1 at %d counts\n",
              task.outputs()[0], static_cast<unsigned long long>(task.steps()),
              task.encoder_next()[0]);
  return static_cast<int>(hiltwin::runtime::ExitCodeFor(report));
}
