// Every way the loader refuses a library, each with its message: where (the spec as typed and
// the file), what is wrong and what to do. Libraries from tests/controllers.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "controller_libs.h"
#include "hiltwin/controller/abi_controller.h"

namespace hiltwin::controller::test {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

struct Refusal {
  const char* library;  ///< tests/controllers/<library>.so
  std::vector<const char*> says;
};

std::ostream& operator<<(std::ostream& out, const Refusal& r) { return out << r.library; }

std::string LoadError(const std::string& path) {
  try {
    (void)LoadAbiController(path);
  } catch (const ControllerError& error) {
    return error.what();
  }
  ADD_FAILURE() << path << " was loaded";
  return "";
}

class AbiRefusal : public ::testing::TestWithParam<Refusal> {};

TEST_P(AbiRefusal, NamesTheFileWhatIsWrongAndWhatToDo) {
  const std::string path = Lib(GetParam().library);
  const std::string message = LoadError(path);
  EXPECT_THAT(message, StartsWith("controller lib:" + path + ": "));
  for (const char* part : GetParam().says) EXPECT_THAT(message, HasSubstr(part));
}

INSTANTIATE_TEST_SUITE_P(
    Libraries, AbiRefusal,
    ::testing::Values(
        Refusal{"no_such_library", {": no such file: build the controller first"}},
        // dlopen's own reason is part of the message.
        Refusal{"not_a_library",
                {"cannot be loaded (", "not_a_library.so: ", "): it is not an ELF file, so "
                 "not a shared library: give the .so the build made"}},
        Refusal{"bad_abi_version",
                {"built against controller ABI version 99, but this hiltwin speaks version 1: "
                 "rebuild the library against the installed hiltwin/controller_abi.h"}},
        Refusal{"bad_no_entry",
                {"the library does not export the symbol hiltwin_controller: define "
                 "`const hiltwin_controller_descriptor* hiltwin_controller(void)`"}},
        Refusal{"bad_null_descriptor", {"hiltwin_controller() returned NULL"}},
        Refusal{"bad_null_step",
                {"the descriptor's entry point step is NULL: every entry point but "
                 "last_error is required"}},
        Refusal{"bad_duplicate_port",
                {"inputs[3]: the input wheel_left_m is listed twice: give every input its own "
                 "name"}},
        Refusal{"bad_null_unit", {"inputs[3] (wheel_right_m) has a NULL unit: give its unit"}},
        Refusal{"bad_no_outputs", {"the controller has no outputs: list its outputs"}}),
    [](const auto& param_info) { return std::string(param_info.param.library); });

TEST(AbiRefusal, AnErrorMessageGivesTheAbsoluteFileWhenThePathIsRelative) {
  const std::string message = LoadError("no/such/dir/my_pd.so");
  EXPECT_THAT(message, StartsWith("controller lib:no/such/dir/my_pd.so ("));
  EXPECT_THAT(message, HasSubstr("/no/such/dir/my_pd.so): no such file"));
}

TEST(AbiRefusal, ALibraryForAnotherMachineIsRefusedNamingBothMachines) {
  const std::string path = Lib("foreign_machine");
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "no arm64 compiler on this x86-64 machine (tests/controllers)";
  }
  const std::string message = LoadError(path);
  EXPECT_THAT(message, StartsWith("controller lib:" + path + ": cannot be loaded ("));
  EXPECT_THAT(message, HasSubstr("): it was built for arm64 (aarch64), but this machine is "
                                 "x86-64 (amd64): build it here, or with a compiler for this "
                                 "machine"));
}

TEST(AbiRefusal, CreateReturningNullIsRefusedAtStart) {
  const auto controller = LoadAbiController(Lib("bad_create_null"));
  try {
    controller->Start(0.001);
    FAIL() << "started without a state";
  } catch (const ControllerError& error) {
    EXPECT_THAT(error.what(), StartsWith("controller lib:" + Lib("bad_create_null") + ": "));
    EXPECT_THAT(error.what(), HasSubstr("its create() returned NULL, so 'test_controller' has "
                                        "no state to run"));
  }
}

TEST(AbiRefusal, AFailingStartIsRefusedWithItsTextAndItsStateDestroyed) {
  const std::string lib = Lib("bad_start_fails");
  auto controller = LoadAbiController(lib);
  const auto base = Calls(lib);
  try {
    controller->Start(0.001);
    FAIL() << "a start() that returned 3 was taken for a start";
  } catch (const ControllerError& error) {
    EXPECT_THAT(error.what(), HasSubstr("its start(step_s = 0.001) returned 3: start refused: "
                                        "the test library was built to refuse; the run did "
                                        "not start"));
  }
  const auto after = Calls(lib);
  EXPECT_EQ(after[4] - base[4], 1);  // destroyed
  EXPECT_EQ(after[3] - base[3], 0);  // not finished: it never ran
  controller->Finish();              // nothing left to finish
  EXPECT_EQ(Calls(lib)[4], after[4]);
}

}  // namespace
}  // namespace hiltwin::controller::test
