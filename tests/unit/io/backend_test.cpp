#include "hiltwin/io/backend.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <string>

#include "hiltwin/io/icoboard.h"

namespace hiltwin::io {
namespace {

TEST(BackendSpec, ParsesTheThreeForms) {
  EXPECT_EQ(ParseBackendSpec("mock").kind, BackendSpec::Kind::kMock);
  const BackendSpec wire = ParseBackendSpec("wire:bench_1.a-b");
  EXPECT_EQ(wire.kind, BackendSpec::Kind::kWire);
  EXPECT_EQ(wire.argument, "bench_1.a-b");
  const BackendSpec spidev = ParseBackendSpec("spidev:/dev/spidev0.1");
  EXPECT_EQ(spidev.kind, BackendSpec::Kind::kSpidev);
  EXPECT_EQ(spidev.argument, "/dev/spidev0.1");
}

TEST(BackendSpec, BadStringsThrowAConfigErrorListingTheAcceptedForms) {
  for (const char* bad : {"", "Mock", "mock:x", "wire:", "wire:a/b", "wire:.hidden", "spidev:",
                          "spidev:/dev/spidev0", "spidev:/dev/tty0", "spidev:/dev/spidev0.x",
                          "serial:/dev/ttyS0", "wire"}) {
    try {
      (void)ParseBackendSpec(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(std::string("'") + bad + "'"), std::string::npos) << what;
      EXPECT_NE(what.find("accepted forms: mock, wire:NAME"), std::string::npos) << what;
      EXPECT_NE(what.find("spidev:/dev/spidevB.C"), std::string::npos) << what;
    }
  }
}

TEST(OpenBackend, MockCarriesTheRequestedBoardImage) {
  BackendOptions options;
  auto matching = OpenBackend("mock", options);
  ASSERT_NE(matching->emulated_board(), nullptr);
  EXPECT_EQ(matching->emulated_board()->image(), Image::kIcoboardInverse);
  IcoBoardInverse twin(matching->bus());
  EXPECT_TRUE(twin.Init(1'000'000).ok);

  options.mock_board_image = Image::kIcoboard;
  auto wrong = OpenBackend("mock", options);
  IcoBoardInverse twin2(wrong->bus());
  const InitResult init = twin2.Init(1'000'000);
  EXPECT_FALSE(init.ok);
  EXPECT_EQ(init.found, Image::kIcoboard);

  // An emulated board may carry the wrong image (mock and wire); a real one carries its own.
  EXPECT_THROW((void)OpenBackend("spidev:/dev/spidev0.0", options), ConfigError);
  const std::string name = "utest-backend-image-" + std::to_string(::getpid());
  auto wired = OpenBackend("wire:" + name, options);
  IcoBoardInverse twin3(wired->bus());
  const InitResult wired_init = twin3.Init(1'000'000);
  EXPECT_FALSE(wired_init.ok);
  EXPECT_EQ(wired_init.found, Image::kIcoboard);
}

TEST(OpenBackend, MissingSpidevIsAnOsErrorNotAConfigError) {
  try {
    (void)OpenBackend("spidev:/dev/spidev97.3", BackendOptions{});
    FAIL() << "a device that does not exist was opened";
  } catch (const ConfigError&) {
    FAIL() << "the string is well formed; the OS refused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/spidev97.3"), std::string::npos);
  }
}

}  // namespace
}  // namespace hiltwin::io
