// `--io verilated`: the spec forms, the factory hook, and a driver INIT through the RTL board.
#include <gtest/gtest.h>

#include "hiltwin/fpga_sim/verilated_backend.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"

namespace hiltwin::fpga_sim {
namespace {

TEST(VerilatedBackend, ParsesItsFormsAndRejectsOtherImages) {
  EXPECT_EQ(io::ParseBackendSpec("verilated").kind, io::BackendSpec::Kind::kVerilated);
  EXPECT_EQ(io::ParseBackendSpec("verilated:icoboard").argument, "icoboard");
  EXPECT_EQ(io::ParseBackendSpec("verilated:icoboard_inverse").argument, "icoboard_inverse");
  EXPECT_THROW((void)io::ParseBackendSpec("verilated:"), io::ConfigError);
  EXPECT_THROW((void)io::ParseBackendSpec("verilated:ecs"), io::ConfigError);
}

TEST(VerilatedBackend, IsRefusedUntilRegisteredThenInitsBothImages) {
  io::RegisterVerilatedBackendFactory(nullptr);
  io::BackendOptions options;
  EXPECT_THROW((void)io::OpenBackend("verilated", options), io::ConfigError);
  RegisterVerilatedBackend();
  for (const io::Image image : {io::Image::kIcoboardInverse, io::Image::kIcoboard}) {
    options.side = image;
    const auto backend = io::OpenBackend("verilated", options);
    EXPECT_EQ(backend->kind(), io::BackendSpec::Kind::kVerilated);
    EXPECT_EQ(backend->emulated_board(), nullptr);
    io::IcoBoardLink link(backend->bus(), image);
    const io::InitResult init = link.Init(250'000);
    EXPECT_TRUE(init.ok) << init.message;
    EXPECT_EQ(init.identity, io::IdentityOf(image));
  }
  // The image named in the spec wins over the side's: the identity check then refuses it.
  options.side = io::Image::kIcoboardInverse;
  const auto wrong = io::OpenBackend("verilated:icoboard", options);
  io::IcoBoardLink link(wrong->bus(), io::Image::kIcoboardInverse);
  const io::InitResult init = link.Init(250'000);
  EXPECT_FALSE(init.ok);
  EXPECT_EQ(init.identity, io::kIdentityIcoboard);
}

TEST(VerilatedBackend, RefusesASpecImageThatContradictsTheChosenBoardImage) {
  RegisterVerilatedBackend();
  io::BackendOptions options;
  options.mock_board_image = io::Image::kIcoboard;
  try {
    (void)io::OpenBackend("verilated:icoboard_inverse", options);
    FAIL() << "two different images for one board were accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'verilated:icoboard_inverse' names the RTL board's "
                                         "image and the board image chosen besides it is "
                                         "icoboard"),
              std::string::npos)
        << e.what();
  }
  // Agreeing, or naming the image only once, opens the board with that image.
  for (const char* spec : {"verilated:icoboard", "verilated"}) {
    const auto backend = io::OpenBackend(spec, options);
    io::IcoBoardLink link(backend->bus(), io::Image::kIcoboard);
    const io::InitResult init = link.Init(250'000);
    EXPECT_TRUE(init.ok) << spec << ": " << init.message;
  }
}

}  // namespace
}  // namespace hiltwin::fpga_sim
