#pragma once
/// FMI 2.0 co-simulation FMUs as plants (`--plant fmu:PATH.fmu`, docs/fmi.md). Opening an FMU
/// does everything that may allocate, load or do I/O: unpack the zip into a private folder,
/// read modelDescription.xml, dlopen binaries/<platform>/<modelIdentifier>.so and look up every
/// function hiltwin calls. Start() instantiates and initialises; Step() is fmi2SetReal ->
/// fmi2DoStep -> fmi2GetReal and nothing else. Ports are the FMU's Real inputs and outputs.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string_view>

#include "hiltwin/fmi/fmi2_abi.h"
#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_registry.h"

namespace hiltwin::fmi {

/// What opening an FMU may unpack at most (docs/fmi.md, "The unpack folder"): far beyond what
/// modelling tools export (a few hundred entries, tens of MiB), far below what fills a $TMPDIR.
/// Entries in the archive, of any kind: libzip reads the central directory whole.
inline constexpr std::uint64_t kMaxFmuEntries = 10'000;
/// Bytes written into the unpack folder: modelDescription.xml, binaries/<platform>/ and
/// resources/ (the only parts unpacked), as declared by each entry and as actually written.
inline constexpr std::uint64_t kMaxFmuUnpackedBytes = std::uint64_t{256} << 20;  // 256 MiB

/// The caps of one opening; the defaults are the constants above.
struct FmuUnpackLimits {
  std::uint64_t max_entries = kMaxFmuEntries;
  std::uint64_t max_bytes = kMaxFmuUnpackedBytes;
};

/// How to open an FMU beyond what the command line gives (tests, benchmarks, embedders).
struct FmuOptions {
  /// loggingOn for fmi2Instantiate: asks the FMU for its debug messages too.
  bool debug_logging = false;
  /// Messages the log ring holds between drains; more are dropped and counted.
  std::size_t log_capacity_messages = 1024;
  /// Where drained log lines go (one line, no newline); empty = stderr.
  std::function<void(std::string_view line)> log_sink;
  /// What unpacking may take at most.
  FmuUnpackLimits unpack_limits;
};

/// The FMU's own functions on the plant's instance, for measuring the adapter against them
/// (bench/fmi). Valid between Start() and Finish().
struct FmuDirectCalls {
  fmi2Component component = nullptr;
  fmi2SetRealTYPE* set_real = nullptr;
  fmi2DoStepTYPE* do_step = nullptr;
  fmi2GetRealTYPE* get_real = nullptr;
  std::span<const fmi2ValueReference> input_refs;
  std::span<const fmi2ValueReference> output_refs;
};

/// A plant backed by an FMU, with what the FMU adds to the plant interface.
class FmuPlant : public plant::Plant {
 public:
  /// Not real-time. Writes the FMU's queued log messages to the sink, and a line with the
  /// number dropped since the last drain if any. Also done at Start, Reset, Finish and
  /// destruction; a helper thread may call it during the run (one drainer at a time is
  /// enforced; the loop thread never waits for it).
  virtual std::size_t DrainLog() = 0;
  /// Log messages dropped because the ring was full, since the plant was opened.
  [[nodiscard]] virtual std::uint64_t log_messages_dropped() const noexcept = 0;
  /// The private folder the FMU was unpacked into; removed when the plant is destroyed.
  [[nodiscard]] virtual const std::filesystem::path& unpack_dir() const noexcept = 0;
  [[nodiscard]] virtual FmuDirectCalls DirectCalls() const noexcept = 0;
};

/// Opens an FMU. Throws plant::PlantError saying which file, entry, attribute or symbol is
/// wrong and what to do: not a zip, more entries or bytes than options.unpack_limits, a damaged
/// entry, no or malformed modelDescription.xml, fmiVersion other than 2.0, Model Exchange
/// only, no binary for this platform (fmu_platform.h), a missing function.
[[nodiscard]] std::unique_ptr<FmuPlant> OpenFmu(const std::filesystem::path& fmu_path,
                                                FmuOptions options = {});

/// `--plant fmu:PATH`: OpenFmu with the command line's options. An FMU brings its own solver
/// and parameters, so a --config or --integrator is refused (PlantError), never ignored.
[[nodiscard]] std::unique_ptr<plant::Plant> OpenFmuPlant(const std::filesystem::path& fmu_path,
                                                         const plant::PlantOptions& options);

}  // namespace hiltwin::fmi
