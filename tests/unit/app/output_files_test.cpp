// CheckFilesDistinct (hiltwin/runs/output_files.h): an output that names the file of an input
// or of another output is refused (exit 2, both flags and paths named, what to do), however
// the two names are spelled; two inputs may share a file, a device is no file to clobber, and
// a built-in profile's name is no file at all.
#include "hiltwin/runs/output_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/runs/command.h"

namespace hiltwin::app {
namespace {

namespace fs = std::filesystem;

class OutputFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_output_files_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "sub");
    std::ofstream(dir_ / "in.csv") << "time,left,right\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  /// The usage error CheckFilesDistinct gives for `files`; "no error" when it accepts them.
  static std::string ErrorOf(const std::vector<NamedFile>& files) {
    try {
      CheckFilesDistinct(files);
    } catch (const CommandError& e) {
      EXPECT_EQ(e.code(), ExitCode::kUsage) << e.what();
      return e.what();
    }
    return "no error";
  }

  fs::path dir_;
};

TEST_F(OutputFiles, AnOutputOnAnInputNamesBothAndWhatToDo) {
  EXPECT_EQ(ErrorOf({{"--input", Path("in.csv"), false}, {"--log", Path("in.csv"), true}}),
            "--log " + Path("in.csv") + " and --input " + Path("in.csv") +
                " name the same file: --log would overwrite the file --input reads; give --log "
                "another file");
}

TEST_F(OutputFiles, TwoOutputsOnOneFileThatDoesNotExistYet) {
  EXPECT_EQ(ErrorOf({{"--log", Path("x.csv"), true}, {"--report", Path("sub/../x.csv"), true}}),
            "--log " + Path("x.csv") + " and --report " + Path("sub/../x.csv") +
                " name the same file: each output would overwrite the other; give each its own "
                "file");
  EXPECT_FALSE(fs::exists(Path("x.csv")));  // checking creates nothing
}

TEST_F(OutputFiles, AHardLinkALinkedFolderAndARelativePathAreTheSameFile) {
  fs::create_hard_link(Path("in.csv"), Path("hard.csv"));
  fs::create_directory_symlink(dir_, Path("linked"));
  fs::create_symlink(Path("in.csv"), Path("link.csv"));
  for (const std::string& other :
       {Path("hard.csv"), Path("linked/in.csv"), Path("link.csv"),
        fs::relative(Path("in.csv")).string()}) {
    EXPECT_NE(ErrorOf({{"--config", Path("in.csv"), false}, {"--report", other, true}}),
              "no error")
        << other;
  }
  // A folder link to a file not there yet: the same absolute path once its links are resolved.
  EXPECT_NE(ErrorOf({{"--log", Path("linked/new.csv"), true}, {"--report", Path("new.csv"), true}}),
            "no error");
}

TEST_F(OutputFiles, InputsMayShareAFileAndDistinctFilesDevicesAndUnsetFlagsPass) {
  EXPECT_EQ(ErrorOf({{"--sim", Path("in.csv"), false}, {"--exp", Path("in.csv"), false}}),
            "no error");
  EXPECT_EQ(ErrorOf({{"--input", Path("in.csv"), false},
                     {"--log", Path("a.csv"), true},
                     {"--timing-log", Path("b.csv"), true},
                     {"--report", "", true},
                     {"--config", "", false}}),
            "no error");
  EXPECT_EQ(ErrorOf({{"--log", "/dev/null", true}, {"--report", "/dev/null", true}}), "no error");
}

TEST_F(OutputFiles, ABuiltInProfileNameIsNoFile) {
  constexpr std::array<std::string_view, 1> kBuiltin{"openloop"};
  EXPECT_EQ(ProfileFile("--input", "openloop", kBuiltin).path, "");
  const NamedFile file = ProfileFile("--input", Path("in.csv"), kBuiltin);
  EXPECT_EQ(file.flag, "--input");
  EXPECT_EQ(file.path, Path("in.csv"));
  EXPECT_FALSE(file.written);
}

}  // namespace
}  // namespace hiltwin::app
