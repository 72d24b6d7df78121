#include "hiltwin/fpga_sim/verilated_backend.h"

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/fpga_sim/verilated_board.h"

namespace hiltwin::fpga_sim {
namespace {

class VerilatedBackend final : public io::IoBackend {
 public:
  explicit VerilatedBackend(io::Image image)
      : bench_(image == io::Image::kIcoboardInverse, image == io::Image::kIcoboard, false),
        device_(bench_, image),
        bus_(device_, image == io::Image::kIcoboard ? "verilated:icoboard"
                                                    : "verilated:icoboard_inverse") {}
  io::SpiBus& bus() noexcept override { return bus_; }
  io::EmulatedFpga* emulated_board() noexcept override { return nullptr; }
  [[nodiscard]] io::BackendSpec::Kind kind() const noexcept override {
    return io::BackendSpec::Kind::kVerilated;
  }
  bool AttachPwmSource(io::PwmSignalSource* source) noexcept override {
    if (device_.image() != io::Image::kIcoboardInverse) return false;
    device_.SetPwmSource(source);
    return true;
  }

 private:
  RtlBench bench_;
  VerilatedBoardDevice device_;
  io::EmulatedSpiBus bus_;
};

}  // namespace

std::unique_ptr<io::IoBackend> OpenVerilatedBackend(std::string_view argument,
                                                    const io::BackendOptions& options) {
  io::Image image = options.mock_board_image.value_or(options.side);
  if (argument == "icoboard") image = io::Image::kIcoboard;
  if (argument == "icoboard_inverse") image = io::Image::kIcoboardInverse;
  return std::make_unique<VerilatedBackend>(image);
}

void RegisterVerilatedBackend() noexcept {
  io::RegisterVerilatedBackendFactory(&OpenVerilatedBackend);
}

}  // namespace hiltwin::fpga_sim
