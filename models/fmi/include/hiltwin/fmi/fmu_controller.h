#pragma once
/// FMI 2.0 co-simulation FMUs as controllers (`--controller fmu:PATH.fmu`, docs/fmi.md, "FMUs
/// as controllers"). The FMU is opened, started and stepped by the FMU plant's machinery
/// (fmu_plant.h: unpack, modelDescription.xml, dlopen, fmi2SetReal -> fmi2DoStep ->
/// fmi2GetReal), so a controller FMU is loaded and checked exactly as a plant FMU is. Ports:
/// the Real variables of causality "input" (encoder readings, setpoints) and "output" (duties),
/// with the units modelDescription.xml gives. Refused besides what the plant refuses: an FMU
/// without a Real output, an output that is not a Real.

#include <filesystem>
#include <memory>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_registry.h"
#include "hiltwin/fmi/fmu_plant.h"

namespace hiltwin::fmi {

/// Opens the FMU at `fmu_path` as a controller (not started). Throws controller::ControllerError
/// saying which file, entry, attribute or symbol is wrong and what to do; also for --gains (an
/// FMU brings its own parameters).
[[nodiscard]] std::unique_ptr<controller::Controller> OpenFmuController(
    const std::filesystem::path& fmu_path, const controller::ControllerOptions& options,
    FmuOptions fmu_options = {});

/// Registers the `fmu` controller kind (`--controller fmu:PATH.fmu`). Call once at start-up.
void RegisterFmuControllerKind();

}  // namespace hiltwin::fmi
