#pragma once
/// The ECS's controller gains and output limit and their TOML file (relbot/ecs_gains.toml),
/// read like relbot.toml by toml_numbers.h: every key carries its unit, every key is required,
/// unknown keys are rejected, values are range-checked, and every error is a ConfigError that
/// says "file:line:column: key: what is wrong; what to do". The built-in gains (DefaultEcsGains)
/// equal the file; a unit test checks it. Gains are continuous-time quantities, so one file
/// serves every ECS rate (the PID discretises them at its period).

#include <filesystem>
#include <span>
#include <string_view>

#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/position_pid.h"
#include "hiltwin/relbot/toml_numbers.h"

namespace hiltwin::app {

/// How one gain appears in the TOML file and which values it accepts.
using EcsGainSpec = TomlNumberSpec<PidGains>;

/// Every key, in file order. The loader, the validator and the tests iterate this.
[[nodiscard]] std::span<const EcsGainSpec> EcsGainSpecs() noexcept;

/// The built-in gains, tuned on the in-process closed loop (RELbot twin at 4 kHz, ECS at
/// 1 kHz, `closedloop` profile); identical to relbot/ecs_gains.toml.
[[nodiscard]] PidGains DefaultEcsGains() noexcept;

/// Checks every value is finite and within its range; throws ConfigError naming
/// `source_name` and the key ("table.key").
void ValidateEcsGains(const PidGains& gains, std::string_view source_name);

/// Parses TOML text. Every key of EcsGainSpecs() is required, unknown tables and keys are
/// rejected. Throws ConfigError with source_name:line:column where known.
[[nodiscard]] PidGains ParseEcsGains(std::string_view toml_text, std::string_view source_name);

/// Reads and parses a gains file. Throws ConfigError (also when it cannot be read).
[[nodiscard]] PidGains LoadEcsGains(const std::filesystem::path& path);

}  // namespace hiltwin::app
