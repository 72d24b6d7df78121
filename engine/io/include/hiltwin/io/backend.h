#pragma once
/// Choosing a backend at run time from a string: `mock`, `wire:NAME`, `spidev:/dev/spidevB.C`,
/// `verilated[:IMAGE]`. The verilated backend (the RTL of board/fpga/ compiled by Verilator) lives
/// in the fpga_sim module, which io does not depend on: fpga_sim registers its factory here
/// (fpga_sim::RegisterVerilatedBackend), and OpenBackend refuses `verilated` until it has.

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/io/peer_link.h"
#include "hiltwin/io/spi_bus.h"
#include "hiltwin/io/spidev_bus.h"

namespace hiltwin::io {

/// A configuration mistake (bad backend string, bad name); the message says what and how to fix.
class ConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The accepted backend forms, for help texts and error messages.
constexpr const char* kBackendForms =
    "mock, wire:NAME (NAME: 1-64 of letters, digits, '_', '-', '.'), "
    "spidev:/dev/spidevB.C (e.g. spidev:/dev/spidev0.0), "
    "verilated[:icoboard|icoboard_inverse] (the RTL under Verilator)";

/// A parsed backend string.
struct BackendSpec {
  enum class Kind { kMock, kWire, kSpidev, kVerilated };
  Kind kind = Kind::kMock;
  std::string argument;  ///< wire name, device path or verilated image (empty: the side's)
};

/// Parses `text`; throws ConfigError naming the text, the problem and kBackendForms.
[[nodiscard]] BackendSpec ParseBackendSpec(std::string_view text);

/// How to open a backend.
struct BackendOptions {
  Image side = Image::kIcoboardInverse;     ///< the image this side's driver needs
  /// mock, wire: the image the emulated board carries (default: side); fault injection
  std::optional<Image> mock_board_image;
  SpidevConfig spidev{};
  /// wire: run in lockstep with the peer on one virtual time base (--clock virtual); the
  /// backend's lockstep_clock() is then the clock the session must run on. Others: ignored.
  bool lockstep = false;
};

/// An opened backend: owns its bus and, for mock and wire, the local emulated board.
class IoBackend {
 public:
  virtual ~IoBackend() = default;
  [[nodiscard]] virtual SpiBus& bus() noexcept = 0;
  /// The local board model (mock, wire) for sources and fault injection; null for spidev.
  [[nodiscard]] virtual EmulatedFpga* emulated_board() noexcept = 0;
  [[nodiscard]] virtual BackendSpec::Kind kind() const noexcept = 0;
  /// The process on the other end (wire); null when there is none to wait for (mock, spidev).
  [[nodiscard]] virtual PeerLink* peer_link() noexcept { return nullptr; }
  /// The virtual clock this backend shares with its peer (wire in lockstep); null otherwise.
  [[nodiscard]] virtual kernel_glue::Clock* lockstep_clock() noexcept { return nullptr; }
  /// Feeds the local twin board's PWM reader from `source` (mock: the emulated board,
  /// verilated: the RTL's PWM inputs). False when this backend has no such input.
  virtual bool AttachPwmSource(PwmSignalSource* source) noexcept {
    EmulatedFpga* board = emulated_board();
    if (board == nullptr) return false;
    board->SetPwmSource(source);
    return true;
  }
};

/// Opens a `verilated` backend: `argument` is the image named in the spec (empty: choose from
/// the options as for mock). Registered by the fpga_sim module.
using VerilatedBackendFactory = std::unique_ptr<IoBackend> (*)(std::string_view argument,
                                                                 const BackendOptions& options);
/// Registers (or, with null, removes) the factory OpenBackend uses for `verilated`.
void RegisterVerilatedBackendFactory(VerilatedBackendFactory factory) noexcept;

/// Opens the backend named by `spec`. Throws ConfigError for a bad string or option, and
/// std::runtime_error when the OS refuses (no such SPI device, /dev/shm unusable).
[[nodiscard]] std::unique_ptr<IoBackend> OpenBackend(std::string_view spec,
                                                     const BackendOptions& options);
/// Opens an already parsed backend (a command parses its flag once, at the command line).
/// Throws as the string form does, for the options; the messages quote the SPEC form.
[[nodiscard]] std::unique_ptr<IoBackend> OpenBackend(const BackendSpec& spec,
                                                     const BackendOptions& options);

}  // namespace hiltwin::io
