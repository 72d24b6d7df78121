// The controller registry (--controller SPEC) and the SHA-256 of a controller's file.
#include "hiltwin/controller/controller_registry.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "fakes/fake_controller.h"
#include "hiltwin/controller/content_hash.h"

namespace hiltwin::controller {
namespace {

using test::FakeController;

std::unique_ptr<Controller> MakeFake(const ControllerOptions&) {
  return std::make_unique<FakeController>(FakeController::RelbotInputs(),
                                          FakeController::RelbotOutputs());
}

// Registered once for the whole binary (a second registration under one name aborts).
const bool kRegistered =
    RegisterController({"regtest", "a fake for the registry test", MakeFake}) &&
    RegisterControllerKind({"regkind", "a fake file kind", [](const std::string& path,
                                                              const ControllerOptions& o) {
                              if (path != "x.so") throw ControllerError("no " + path);
                              return MakeFake(o);
                            }});

TEST(ControllerRegistry, ANameAndAPrefixedFileFindTheirFactories) {
  ASSERT_TRUE(kRegistered);
  EXPECT_NE(FindController("regtest"), nullptr);
  EXPECT_EQ(FindController("regkind"), nullptr);
  EXPECT_EQ(MakeController("regtest", {})->Info().name, "fake");
  EXPECT_EQ(MakeController("regkind:x.so", {})->Info().name, "fake");
  EXPECT_THROW(static_cast<void>(MakeController("regkind:y.so", {})), ControllerError);
  bool listed = false;
  for (const ControllerKind* kind : RegisteredControllerKinds()) {
    listed = listed || kind->prefix == "regkind";
  }
  EXPECT_TRUE(listed);
}

TEST(ControllerRegistry, AnUnknownSpecIsRefusedListingWhatExists) {
  try {
    static_cast<void>(MakeController("pdi", {}));
    FAIL() << "no error";
  } catch (const ControllerError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("--controller pdi: no such controller; give one of: ", 0), 0U) << what;
    EXPECT_NE(what.find("regtest (a fake for the registry test)"), std::string::npos) << what;
    EXPECT_NE(what.find("regkind:PATH (a fake file kind)"), std::string::npos) << what;
    EXPECT_NE(what.find("(docs/controllers.md)"), std::string::npos) << what;
  }
  try {
    static_cast<void>(MakeController("regkind:", {}));
    FAIL() << "no error";
  } catch (const ControllerError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--controller regkind:: nothing after 'regkind:': give regkind:PATH");
  }
}

TEST(ContentHash, TheSha256OfAFileIsItsBytesDigestInLowerCaseHex) {
  const std::string path = ::testing::TempDir() + "/content_hash_abc.txt";
  std::ofstream(path, std::ios::binary) << "abc";
  // FIPS 180-2's example digest of "abc".
  EXPECT_EQ(Sha256HexOfFile(path),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  try {
    static_cast<void>(Sha256HexOfFile("/nonexistent/x.so"));
    FAIL() << "no error";
  } catch (const ControllerError& e) {
    EXPECT_EQ(std::string(e.what()),
              "/nonexistent/x.so: cannot hash the controller's file (No such file or directory): "
              "check that it is readable");
  }
}

}  // namespace
}  // namespace hiltwin::controller
