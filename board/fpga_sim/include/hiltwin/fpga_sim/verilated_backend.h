#pragma once
/// `--io verilated[:icoboard|icoboard_inverse]`: one verilated board alone on its own RtlBench,
/// behind an emulated bus named "verilated", where `--io mock` puts io::EmulatedFpga. Its inputs
/// are idle unless a PWM source is attached (the twin's profile); the A/B inputs of an ECS board
/// alone are held still.

#include <memory>
#include <string_view>

#include "hiltwin/io/backend.h"

namespace hiltwin::fpga_sim {

/// Makes io::OpenBackend accept `verilated` (idempotent; call once at start-up).
void RegisterVerilatedBackend() noexcept;

/// The factory RegisterVerilatedBackend installs (for tests and for programs that wire it up
/// themselves).
[[nodiscard]] std::unique_ptr<io::IoBackend> OpenVerilatedBackend(std::string_view argument,
                                                                  const io::BackendOptions& options);

}  // namespace hiltwin::fpga_sim
