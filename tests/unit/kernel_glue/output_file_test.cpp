// OpenOutputFile: user-named output files are created or truncated, never written through a
// symbolic link, and every refusal names the flag, the path and the fix. ReplacementFile: a
// report replaces the old file only once it is whole, refuses what OpenOutputFile refuses, and
// leaves no temporary file behind.
#include "hiltwin/kernel_glue/output_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fcntl.h>

#include <sys/stat.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace hiltwin::kernel_glue {
namespace {

namespace fs = std::filesystem;

class OutputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_output_file_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  static std::string ReadText(const std::string& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  // The error OpenOutputFile throws for `path` (fails the test when it opens).
  static OutputFileError ErrorFor(const std::string& path, const std::string& name) {
    try {
      const int fd = OpenOutputFile(path, name);
      ::close(fd);
    } catch (const OutputFileError& e) {
      return e;
    }
    ADD_FAILURE() << path << " opened";
    return OutputFileError(name, path, "", 0);
  }

  fs::path dir_;
};

TEST_F(OutputFileTest, CreatesANewFileAndTruncatesAnOldOne) {
  std::ofstream(Path("old.csv")) << "old contents\n";
  for (const std::string name : {"new.csv", "old.csv"}) {
    const int fd = OpenOutputFile(Path(name), "--log");
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::write(fd, "x\n", 2), 2);
    EXPECT_NE(::fcntl(fd, F_GETFD) & FD_CLOEXEC, 0);  // not inherited by a child process
    ::close(fd);
    EXPECT_EQ(ReadText(Path(name)), "x\n");
  }
}

TEST_F(OutputFileTest, RefusesAFinalSymbolicLinkAndLeavesItsTargetAlone) {
  std::ofstream(Path("precious")) << "keep\n";
  fs::create_symlink(Path("precious"), Path("run.csv"));
  const OutputFileError e = ErrorFor(Path("run.csv"), "--log");
  EXPECT_EQ(std::string(e.what()), "--log " + Path("run.csv") + " is a symbolic link (to " +
                                       Path("precious") +
                                       "); hiltwin does not write through links: name the real "
                                       "file");
  EXPECT_EQ(e.path(), Path("run.csv"));
  EXPECT_EQ(e.MessageFor("--timing-log").rfind("--timing-log " + Path("run.csv") + " is a", 0),
            0U);
  EXPECT_EQ(ReadText(Path("precious")), "keep\n");
}

TEST_F(OutputFileTest, ADanglingLinkCreatesNothing) {
  fs::create_symlink(Path("elsewhere.csv"), Path("run.csv"));
  const OutputFileError e = ErrorFor(Path("run.csv"), "--log");
  EXPECT_NE(std::string(e.what()).find("is a symbolic link (to " + Path("elsewhere.csv") + ")"),
            std::string::npos)
      << e.what();
  EXPECT_FALSE(fs::exists(Path("elsewhere.csv")));
}

TEST_F(OutputFileTest, FollowsALinkedFolderTheUserNamed) {
  fs::create_directories(Path("real"));
  fs::create_directory_symlink(Path("real"), Path("linked"));
  const int fd = OpenOutputFile(Path("linked/r.json"), "--report");
  ASSERT_GE(fd, 0);
  ::close(fd);
  EXPECT_TRUE(fs::is_regular_file(Path("real/r.json")));
}

TEST_F(OutputFileTest, AMissingFolderAFolderAndAFileAsFolderAreExplained) {
  EXPECT_EQ(std::string(ErrorFor(Path("nope/r.json"), "--report").what()),
            "--report " + Path("nope/r.json") + ": the folder '" + Path("nope") +
                "' does not exist; create it first");
  EXPECT_EQ(std::string(ErrorFor(dir_.string(), "--report").what()),
            "--report " + dir_.string() + " is a folder; name a file inside it");
  std::ofstream(Path("plain")) << "x";
  const OutputFileError e = ErrorFor(Path("plain/r.json"), "--report");
  EXPECT_EQ(e.error_number(), ENOTDIR);
  EXPECT_NE(std::string(e.what()).find("is not a folder"), std::string::npos) << e.what();
}

TEST_F(OutputFileTest, AReplacementReplacesTheOldFileOnlyWhenCommitted) {
  std::ofstream(Path("r.json")) << "previous\n";
  {
    ReplacementFile file(Path("r.json"), "--report");
    ASSERT_TRUE(file.is_open());
    // Beside the report, hidden, in the same folder (one file system: rename is atomic).
    EXPECT_EQ(fs::path(file.temporary_path()).parent_path(), dir_);
    EXPECT_EQ(fs::path(file.temporary_path()).filename().string().rfind(".r.json.hiltwin-", 0),
              0U);
    EXPECT_TRUE(fs::exists(file.temporary_path()));
    EXPECT_EQ(ReadText(Path("r.json")), "previous\n");
    EXPECT_EQ(file.Commit("new\n"), 0);
    EXPECT_FALSE(file.is_open());
    EXPECT_EQ(file.Commit("again\n"), EBADF);  // once only
  }
  EXPECT_EQ(ReadText(Path("r.json")), "new\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(OutputFileTest, AReplacementNeverCommittedLeavesTheOldFileAndNoTemporaryFile) {
  std::ofstream(Path("r.json")) << "previous\n";
  { const ReplacementFile file(Path("r.json"), "--report"); }
  { const ReplacementFile file(Path("new.json"), "--report"); }
  EXPECT_EQ(ReadText(Path("r.json")), "previous\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(OutputFileTest, AReplacementRefusesWhatOpenOutputFileRefusesNamingThePath) {
  std::ofstream(Path("precious")) << "keep\n";
  fs::create_symlink(Path("precious"), Path("link.json"));
  for (const std::string& path : {Path("link.json"), Path("nope/r.json"), dir_.string()}) {
    const std::string expected = ErrorFor(path, "--report").what();
    try {
      const ReplacementFile file(path, "--report");
      ADD_FAILURE() << path << " opened";
    } catch (const OutputFileError& e) {
      EXPECT_EQ(std::string(e.what()), expected);
      EXPECT_EQ(e.path(), path);
    }
  }
  EXPECT_EQ(ReadText(Path("precious")), "keep\n");
  EXPECT_TRUE(fs::is_symlink(Path("link.json")));
}

TEST_F(OutputFileTest, AReplacementOfADeviceWritesIntoItInPlace) {
  ReplacementFile file("/dev/null", "--report");
  EXPECT_TRUE(file.temporary_path().empty());
  EXPECT_EQ(file.Commit("discarded\n"), 0);
  struct stat status {};
  ASSERT_EQ(::stat("/dev/null", &status), 0);
  EXPECT_TRUE(S_ISCHR(status.st_mode));  // the device node is still there, not a file
}

}  // namespace
}  // namespace hiltwin::kernel_glue
