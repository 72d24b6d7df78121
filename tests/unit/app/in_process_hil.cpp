#include "in_process_hil.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/relbot/pid_controller.h"

namespace hiltwin::app::test {
namespace {

std::uint64_t TwinPerEcs(const HilConfig& config) {
  const double ratio = config.twin_rate_hz / config.ecs_rate_hz;
  if (!(ratio >= 1.0) || ratio != std::floor(ratio)) {
    throw std::invalid_argument("the twin's rate must be a whole multiple of the ECS's");
  }
  return static_cast<std::uint64_t>(ratio);
}

double LengthS(const HilConfig& config) {
  if (config.duration_s > 0.0) return config.duration_s;
  return config.setpoints != nullptr ? config.setpoints->length_s()
                                     : config.duty_profile->period_s();
}

class EmulatedBoards final : public HilBoards {
 public:
  EmulatedBoards() noexcept {
    ecs_board_.SetEncoderSource(&encoder_lines_);
    twin_board_.SetPwmSource(&pwm_lines_);
  }
  io::SpiBus& twin_bus() noexcept override { return twin_bus_; }
  io::SpiBus& ecs_bus() noexcept override { return ecs_bus_; }
  std::int64_t twin_time_ns() const noexcept override { return twin_board_.time_ns(); }
  std::int64_t ecs_time_ns() const noexcept override { return ecs_board_.time_ns(); }
  std::uint64_t ecs_data_frames() const noexcept override { return ecs_board_.data_frames(); }
  std::uint64_t line_errors() const noexcept override {
    const io::EncoderLineCounters lines = ecs_board_.encoder_lines().counters();
    return lines.illegal_transitions + lines.too_fast_edges + lines.resyncs;
  }

 private:
  io::EmulatedFpga twin_board_{io::Image::kIcoboardInverse};
  io::EmulatedFpga ecs_board_{io::Image::kIcoboard};
  io::EmulatorToReaderLink encoder_lines_{twin_board_};
  io::GeneratorToReaderLink pwm_lines_{ecs_board_};
  io::EmulatedSpiBus twin_bus_{twin_board_};
  io::EmulatedSpiBus ecs_bus_{ecs_board_};
};

/// The ECS as the configuration asks: open loop, the built-in PID, or another controller.
EcsTask MakeEcs(const HilConfig& config, io::IcoBoard& driver, const io::WheelGeometry& geometry,
                std::int64_t period_ns) {
  if (config.setpoints == nullptr) return {driver, *config.duty_profile, geometry, period_ns};
  if (config.controller == nullptr) {
    return {driver, *config.setpoints, config.gains, geometry, period_ns};
  }
  return {driver, *config.setpoints, *config.controller,
          controller::BindControllerMap(RelbotControllerMap(geometry), *config.controller),
          geometry, period_ns};
}

}  // namespace

std::unique_ptr<HilBoards> MakeEmulatedBoards() { return std::make_unique<EmulatedBoards>(); }

InProcessHil::InProcessHil(const HilConfig& config, std::unique_ptr<HilBoards> boards)
    : config_(config),
      ecs_period_ns_(kernel_glue::PeriodNsFromRateHz(config.ecs_rate_hz)),
      twin_period_ns_(kernel_glue::PeriodNsFromRateHz(config.twin_rate_hz)),
      twin_per_ecs_(TwinPerEcs(config)),
      planned_cycles_(
          static_cast<std::uint64_t>(std::llround(LengthS(config) * config.ecs_rate_hz))),
      rest_from_s_(LengthS(config) - config.rest_window_s),
      params_(DefaultRelbotParams()),
      geometry_(WheelGeometryOf(params_)),
      count_m_(1.0 / io::CountsPerMetre(geometry_)),
      boards_(std::move(boards)),
      twin_driver_(boards_->twin_bus()),
      ecs_driver_(boards_->ecs_bus()),
      twin_(twin_driver_, params_, Integrator::kRk4, 1.0 / config.twin_rate_hz),
      ecs_(MakeEcs(config, ecs_driver_, geometry_, ecs_period_ns_)) {
  if (!twin_driver_.Init(twin_period_ns_).ok || !ecs_driver_.Init(ecs_period_ns_).ok) {
    throw std::runtime_error("the boards refused INIT");
  }
}

io::ExchangeStatus InProcessHil::Exchange(bool live_outputs) noexcept {
  const io::ExchangeStatus status = ecs_.Exchange(live_outputs);
  if (!status.ok()) ++seen_.link_errors;
  return status;
}

runtime::StepStatus InProcessHil::Step(const scheduler::CycleContext& context) noexcept {
  const runtime::StepStatus ecs_status = ecs_.Step(context);
  if (ecs_status.code != runtime::StepStatus::Code::kOk) return ecs_status;
  Observe(context.cycle);
  for (std::uint64_t i = 0; i < twin_per_ecs_; ++i, ++twin_cycle_) {
    if (!twin_.task().Exchange(true).ok()) ++seen_.link_errors;
    scheduler::CycleContext twin_context;
    twin_context.cycle = twin_cycle_;
    twin_context.period_ns = twin_period_ns_;
    twin_context.release_ns = static_cast<std::int64_t>(twin_cycle_) * twin_period_ns_;
    twin_context.model_time_ns = twin_context.release_ns;
    if (boards_->twin_time_ns() != twin_context.release_ns) ++seen_.board_time_mismatches;
    const runtime::StepStatus twin_status = twin_.task().Step(twin_context);
    if (twin_status.code != runtime::StepStatus::Code::kOk) return twin_status;
  }
  return runtime::StepStatus::Ok();
}

void InProcessHil::Observe(std::uint64_t ecs_cycle) noexcept {
  ++seen_.ecs_cycles;
  if (boards_->ecs_time_ns() != static_cast<std::int64_t>(ecs_cycle) * ecs_period_ns_ ||
      boards_->ecs_data_frames() != ecs_cycle + 1) {
    ++seen_.board_time_mismatches;
  }
  const EcsCycleRecord& r = ecs_.last();
  // The model has integrated up to t_k exactly when the ECS samples (twin cycles 0 .. r·k - 1).
  const RelbotOutputs truth = twin_.outputs();
  if (ecs_.mode() == EcsMode::kClosedLoop) {
    seen_.final_true_error_left_m = r.setpoint.left_m - truth.wheel_left_m;
    seen_.final_true_error_right_m = r.setpoint.right_m - truth.wheel_right_m;
    seen_.max_abs_true_error_left_m =
        std::max(seen_.max_abs_true_error_left_m, std::abs(seen_.final_true_error_left_m));
    seen_.max_abs_true_error_right_m =
        std::max(seen_.max_abs_true_error_right_m, std::abs(seen_.final_true_error_right_m));
    const double error_left_m = r.setpoint.left_m - r.measured.left_m;
    const double error_right_m = r.setpoint.right_m - r.measured.right_m;
    if (std::max(std::abs(error_left_m), std::abs(error_right_m)) > count_m_) {
      seen_.last_error_above_one_count_s = r.time_s;
    }
  }
  if (r.time_s < rest_from_s_) return;
  const double left = r.duty_next.left;
  const double right = r.duty_next.right;
  if (!rest_seen_) {
    rest_seen_ = true;
    seen_.rest_min_duty = std::min(left, right);
    seen_.rest_max_duty = std::max(left, right);
    seen_.rest_min_counts = std::min(r.counts[0], r.counts[1]);
    seen_.rest_max_counts = std::max(r.counts[0], r.counts[1]);
  } else {
    seen_.rest_duty_sign_changes += (left * last_rest_duty_left_ < 0.0 ? 1U : 0U) +
                                    (right * last_rest_duty_right_ < 0.0 ? 1U : 0U);
  }
  seen_.rest_min_duty = std::min({seen_.rest_min_duty, left, right});
  seen_.rest_max_duty = std::max({seen_.rest_max_duty, left, right});
  seen_.rest_min_counts = std::min({seen_.rest_min_counts, r.counts[0], r.counts[1]});
  seen_.rest_max_counts = std::max({seen_.rest_max_counts, r.counts[0], r.counts[1]});
  if (left != 0.0) last_rest_duty_left_ = left;
  if (right != 0.0) last_rest_duty_right_ = right;
}

HilObservations InProcessHil::observations() const noexcept {
  HilObservations seen = seen_;
  seen.twin_cycles = twin_cycle_;
  seen.line_errors = boards_->line_errors();
  return seen;
}

void RunInProcess(InProcessHil& rig) {
  for (std::uint64_t k = 0; k < rig.planned_cycles(); ++k) {
    (void)rig.Exchange(true);
    scheduler::CycleContext context;
    context.cycle = k;
    context.period_ns = rig.ecs_period_ns();
    context.release_ns = static_cast<std::int64_t>(k) * rig.ecs_period_ns();
    context.model_time_ns = context.release_ns;
    const runtime::StepStatus status = rig.Step(context);
    if (status.code != runtime::StepStatus::Code::kOk) {
      ADD_FAILURE() << "cycle " << k << ": the step failed: " << status.reason;
      return;
    }
  }
}

}  // namespace hiltwin::app::test
