#include "hiltwin/io/backend.h"

#include <atomic>

#include "hiltwin/io/wire_bus.h"

namespace hiltwin::io {
namespace {

bool AllDigits(std::string_view text) noexcept {
  if (text.empty()) return false;
  for (const char ch : text) {
    if (ch < '0' || ch > '9') return false;
  }
  return true;
}

[[noreturn]] void Reject(std::string_view text, const std::string& problem) {
  throw ConfigError("I/O backend '" + std::string(text) + "': " + problem +
                    "; accepted forms: " + kBackendForms);
}

class MockBackend final : public IoBackend {
 public:
  explicit MockBackend(Image board_image) : board_(board_image), bus_(board_, "mock") {}
  SpiBus& bus() noexcept override { return bus_; }
  EmulatedFpga* emulated_board() noexcept override { return &board_; }
  BackendSpec::Kind kind() const noexcept override { return BackendSpec::Kind::kMock; }

 private:
  EmulatedFpga board_;
  EmulatedSpiBus bus_;
};

class WireBackend final : public IoBackend {
 public:
  WireBackend(const std::string& name, Image side, std::optional<Image> board_image,
              WireClock clock)
      : bus_(name, side, board_image, clock) {}
  SpiBus& bus() noexcept override { return bus_; }
  EmulatedFpga* emulated_board() noexcept override { return &bus_.board(); }
  BackendSpec::Kind kind() const noexcept override { return BackendSpec::Kind::kWire; }
  PeerLink* peer_link() noexcept override { return &bus_; }
  kernel_glue::Clock* lockstep_clock() noexcept override { return bus_.lockstep_clock(); }

 private:
  WireBus bus_;
};

class SpidevBackend final : public IoBackend {
 public:
  SpidevBackend(const std::string& path, const SpidevConfig& config) : bus_(path, config) {}
  SpiBus& bus() noexcept override { return bus_; }
  EmulatedFpga* emulated_board() noexcept override { return nullptr; }
  BackendSpec::Kind kind() const noexcept override { return BackendSpec::Kind::kSpidev; }

 private:
  SpidevBus bus_;
};

std::atomic<VerilatedBackendFactory> verilated_factory{nullptr};

/// The SPEC form of a parsed backend, for messages: the text ParseBackendSpec read.
std::string SpecText(const BackendSpec& spec) {
  switch (spec.kind) {
    case BackendSpec::Kind::kMock:
      return "mock";
    case BackendSpec::Kind::kWire:
      return "wire:" + spec.argument;
    case BackendSpec::Kind::kSpidev:
      return "spidev:" + spec.argument;
    case BackendSpec::Kind::kVerilated:
      return spec.argument.empty() ? "verilated" : "verilated:" + spec.argument;
  }
  return "?";
}

}  // namespace

void RegisterVerilatedBackendFactory(VerilatedBackendFactory factory) noexcept {
  verilated_factory.store(factory);
}

BackendSpec ParseBackendSpec(std::string_view text) {
  if (text == "mock") return {BackendSpec::Kind::kMock, ""};
  if (text == "verilated") return {BackendSpec::Kind::kVerilated, ""};
  const auto colon = text.find(':');
  if (colon == std::string_view::npos) {
    Reject(text, text.empty() ? "empty" : "unknown backend");
  }
  const std::string_view kind = text.substr(0, colon);
  const std::string_view argument = text.substr(colon + 1);
  if (kind == "wire") {
    try {
      (void)WireBus::SegmentName(std::string(argument));
    } catch (const std::invalid_argument& e) {
      Reject(text, e.what());
    }
    return {BackendSpec::Kind::kWire, std::string(argument)};
  }
  if (kind == "spidev") {
    constexpr std::string_view kPrefix = "/dev/spidev";
    const bool prefixed = argument.substr(0, kPrefix.size()) == kPrefix;
    const std::string_view numbers = prefixed ? argument.substr(kPrefix.size()) : std::string_view{};
    const auto dot = numbers.find('.');
    if (!prefixed || dot == std::string_view::npos || !AllDigits(numbers.substr(0, dot)) ||
        !AllDigits(numbers.substr(dot + 1))) {
      Reject(text, "the device must be /dev/spidevB.C with bus B and chip select C");
    }
    return {BackendSpec::Kind::kSpidev, std::string(argument)};
  }
  if (kind == "verilated") {
    if (argument != "icoboard" && argument != "icoboard_inverse") {
      Reject(text, "the verilated board's image must be icoboard or icoboard_inverse");
    }
    return {BackendSpec::Kind::kVerilated, std::string(argument)};
  }
  if (kind == "mock") Reject(text, "mock takes no argument");
  Reject(text, "unknown backend '" + std::string(kind) + "'");
}

std::unique_ptr<IoBackend> OpenBackend(std::string_view spec, const BackendOptions& options) {
  return OpenBackend(ParseBackendSpec(spec), options);
}

std::unique_ptr<IoBackend> OpenBackend(const BackendSpec& parsed, const BackendOptions& options) {
  const std::string spec = SpecText(parsed);
  if (options.mock_board_image && parsed.kind == BackendSpec::Kind::kSpidev) {
    throw ConfigError("a board image can only be chosen for an emulated board (mock, wire, "
                      "verilated), "
                      "not for '" + spec + "': the real board carries its own image");
  }
  if (parsed.kind == BackendSpec::Kind::kVerilated && !parsed.argument.empty() &&
      options.mock_board_image && ParseImage(parsed.argument) != options.mock_board_image) {
    // Two flags naming two images for one board: neither may win silently.
    throw ConfigError("'" + spec + "' names the RTL board's image and the board "
                      "image chosen besides it is " + ToString(*options.mock_board_image) +
                      ": name the image once (--io verilated:IMAGE)");
  }
  switch (parsed.kind) {
    case BackendSpec::Kind::kMock:
      return std::make_unique<MockBackend>(options.mock_board_image.value_or(options.side));
    case BackendSpec::Kind::kWire:
      try {
        return std::make_unique<WireBackend>(
            parsed.argument, options.side, options.mock_board_image,
            options.lockstep ? WireClock::kLockstep : WireClock::kRealtime);
      } catch (const std::invalid_argument& e) {  // a peer on the other clock: the user's mix
        throw ConfigError("'" + spec + "': " + e.what());
      }
    case BackendSpec::Kind::kSpidev:
      return std::make_unique<SpidevBackend>(parsed.argument, options.spidev);
    case BackendSpec::Kind::kVerilated: {
      const VerilatedBackendFactory factory = verilated_factory.load();
      if (factory == nullptr) {
        throw ConfigError("I/O backend '" + spec +
                          "': this program has no verilated boards (build with "
                          "-DHILTWIN_FPGA_SIM=ON and apt-get install verilator)");
      }
      return factory(parsed.argument, options);
    }
  }
  throw ConfigError("unreachable backend kind");
}

}  // namespace hiltwin::io
