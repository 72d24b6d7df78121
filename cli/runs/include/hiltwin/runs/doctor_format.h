#pragma once
/// How `hiltwin doctor` shows the RT readiness probe: the table a person reads and the JSON a
/// script reads. The probe returns data; advice about the command's own flags is added here.

#include <nlohmann/json.hpp>
#include <string>

#include "hiltwin/kernel_glue/rt_probe.h"

namespace hiltwin::app {

/// What to do about `check`: the probe's advice, or for a try skipped by --no-try, how to make it.
[[nodiscard]] std::string DoctorAdvice(const kernel_glue::ProbeCheck& check);

/// {"checks": [{id, name, value, status, advice}...], "summary": {ok, warn, bad}}.
[[nodiscard]] nlohmann::json DoctorJson(const kernel_glue::ProbeReport& report);

/// Aligned columns (check, status, value) with the advice wrapped below each line, then the
/// counts ("9 ok, 5 warn, 1 bad").
[[nodiscard]] std::string DoctorText(const kernel_glue::ProbeReport& report);

}  // namespace hiltwin::app
