#pragma once
// modelDescription.xml as a typed struct: what hiltwin needs to run an FMI 2.0 co-simulation
// FMU, checked when read so later code can trust it.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hiltwin::fmi {

struct ScalarVariable {
  std::string name;
  std::uint32_t value_reference = 0;
  std::string causality = "local";  ///< the standard's default
  std::string type;                 ///< "Real", "Integer", "Boolean", "String", "Enumeration"
  std::string unit;                 ///< Real only: its own unit, else its declared type's
  long line = 0;                    ///< in modelDescription.xml, for messages
};

struct ModelDescription {
  std::string fmi_version;
  std::string model_name;
  std::string guid;
  std::string generation_tool;
  std::string model_identifier;          ///< <CoSimulation modelIdentifier=...>
  std::optional<double> default_step_s;  ///< <DefaultExperiment stepSize=...>
  std::vector<ScalarVariable> variables;

  [[nodiscard]] const ScalarVariable* Find(std::string_view name) const noexcept;
};

/// Reads and checks `xml_file`. `fmu_name` names the FMU in messages. Throws plant::PlantError
/// with file:line for: not well-formed XML, another root, fmiVersion other than "2.0", no
/// guid, no <CoSimulation> (Model Exchange only), a variable without a name, value reference
/// or type, and a name used twice.
[[nodiscard]] ModelDescription ReadModelDescription(const std::filesystem::path& xml_file,
                                                    std::string_view fmu_name);

}  // namespace hiltwin::fmi
