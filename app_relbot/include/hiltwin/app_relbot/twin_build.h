#pragma once
/// The RELbot twin behind its FPGA link, built from `run`'s flags: parameters, integrator,
/// input profile, board, model and task, owned together. `hiltwin run` builds one per run;
/// `hiltwin tune` builds one per measured or validated rate, so both run the identical twin.

#include <memory>
#include <optional>
#include <string>

#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/integrator.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/app_relbot/twin_run.h"
#include "hiltwin/app_relbot/twin_task.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::app {

/// Everything the twin's task uses; the task refers into it, so it is never moved.
struct Twin {
  RelbotParams params = DefaultRelbotParams();
  Integrator integrator = Integrator::kRk4;
  std::optional<InputProfile> profile;
  std::unique_ptr<io::IoBackend> backend;
  std::unique_ptr<ProfilePwmSource> pwm_source;
  std::unique_ptr<io::IcoBoardInverse> driver;
  std::optional<RelbotModel> model;
  io::WheelGeometry geometry;
  std::optional<TwinTask> task;
  std::string input_name;
};

/// Reads --config, --integrator and --input (exit 2 naming the problem) into `twin`.
void LoadTwinConfiguration(const TwinRunOptions& o, Twin& twin);

/// Builds the model (a rate it cannot integrate stably is refused here, exit 2), opens the
/// link and checks the board's identity (exit 2 / 5), then builds the task. `o` must be
/// checked (CheckTwinRunOptions) and its controller rate set.
[[nodiscard]] std::unique_ptr<Twin> BuildTwin(const TwinRunOptions& o,
                                              kernel_glue::TimeNs period_ns);

}  // namespace hiltwin::app
