// Every way an FMU is refused at open: a PlantError (exit 2 in the commands) whose message
// names the file, the entry or line, and the reason. A refused FMU leaves no folder behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zip.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "fmu_archive.h"
#include "hiltwin/fmi/fmu_plant.h"
#include "test_fmus.h"

namespace hiltwin::fmi {
namespace {

using test::TestFmu;
using ::testing::AllOf;
using ::testing::HasSubstr;

std::string OpenError(const std::filesystem::path& fmu) {
  try {
    (void)OpenFmu(fmu);
  } catch (const plant::PlantError& error) {
    return error.what();
  }
  ADD_FAILURE() << fmu << " opened";
  return {};
}

// TMPDIR pointed at an empty folder of the test's, to see what unpacking leaves behind.
class FmuRefused : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* old = std::getenv("TMPDIR");  // NOLINT(concurrency-mt-unsafe): one thread
    old_tmpdir_ = old != nullptr ? old : "";
    had_tmpdir_ = old != nullptr;
    tmp_ =
        std::filesystem::temp_directory_path() / ("hiltwin-fmi-test-" + std::to_string(::getpid()));
    std::filesystem::remove_all(tmp_);
    std::filesystem::create_directories(tmp_ / "unpack");
    ::setenv("TMPDIR", (tmp_ / "unpack").c_str(), 1);  // NOLINT(concurrency-mt-unsafe): one thread
  }
  void TearDown() override {
    if (had_tmpdir_) {
      ::setenv("TMPDIR", old_tmpdir_.c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
    } else {
      ::unsetenv("TMPDIR");  // NOLINT(concurrency-mt-unsafe)
    }
    std::filesystem::remove_all(tmp_);
  }
  [[nodiscard]] bool NothingLeftBehind() const {
    return std::filesystem::is_empty(tmp_ / "unpack");
  }
  // A zip with the given entries (name, content), made with libzip as a hostile tool would.
  [[nodiscard]] std::filesystem::path MakeZip(
      const std::string& name, const std::vector<std::pair<std::string, std::string>>& entries) {
    std::filesystem::path path = tmp_ / name;
    int error = 0;
    zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
    EXPECT_NE(archive, nullptr);
    for (const auto& [entry, content] : entries) {
      zip_source_t* source = zip_source_buffer(archive, content.data(), content.size(), 0);
      EXPECT_GE(zip_file_add(archive, entry.c_str(), source, ZIP_FL_ENC_UTF_8), 0) << entry;
    }
    EXPECT_EQ(zip_close(archive), 0);
    return path;
  }

  std::filesystem::path tmp_;

 private:
  std::string old_tmpdir_;
  bool had_tmpdir_ = false;
};

TEST_F(FmuRefused, NotAZipArchive) {
  EXPECT_THAT(OpenError(TestFmu("bad_corrupt")),
              AllOf(HasSubstr("bad_corrupt.fmu: not a readable FMU"), HasSubstr("zip archive"),
                    HasSubstr("libzip says: Not a zip archive")));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST_F(FmuRefused, NoSuchFile) {
  EXPECT_THAT(OpenError(tmp_ / "absent.fmu"),
              AllOf(HasSubstr("absent.fmu: not a readable FMU"), HasSubstr("No such file")));
}

TEST_F(FmuRefused, NoModelDescription) {
  EXPECT_THAT(OpenError(TestFmu("bad_no_xml")),
              AllOf(HasSubstr("bad_no_xml.fmu: no modelDescription.xml at the top")));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST_F(FmuRefused, MalformedXmlWithItsLine) {
  EXPECT_THAT(OpenError(TestFmu("bad_malformed")),
              AllOf(HasSubstr("bad_malformed.fmu: modelDescription.xml:8: not well-formed XML"),
                    HasSubstr("ScalarVariable")));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST_F(FmuRefused, FmiVersionOtherThanTwo) {
  EXPECT_THAT(OpenError(TestFmu("bad_fmi1")),
              AllOf(HasSubstr("bad_fmi1.fmu: modelDescription.xml:4: fmiVersion is \"1.0\""),
                    HasSubstr("FMI 2.0 only")));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST_F(FmuRefused, ModelExchangeOnly) {
  EXPECT_THAT(OpenError(TestFmu("bad_me_only")),
              AllOf(HasSubstr("bad_me_only.fmu: modelDescription.xml:4: a ModelExchange-only FMU"),
                    HasSubstr("export the model for co-simulation")));
}

TEST_F(FmuRefused, NoLinuxBinary) {
  EXPECT_THAT(
      OpenError(TestFmu("bad_no_binary")),
      AllOf(HasSubstr("bad_no_binary.fmu: no binaries/" HILTWIN_FMU_PLATFORM "/bad_no_binary.so"),
            HasSubstr("binaries for: none")));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST_F(FmuRefused, MissingFunction) {
  EXPECT_THAT(OpenError(TestFmu("bad_no_dostep")),
              HasSubstr("bad_no_dostep.fmu: binaries/" HILTWIN_FMU_PLATFORM
                        "/bad_no_dostep.so does not export fmi2DoStep"));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST_F(FmuRefused, EntriesThatWouldUnpackOutsideTheFolder) {
  const std::filesystem::path dotdot =
      MakeZip("dotdot.fmu", {{"modelDescription.xml", "<x/>"}, {"../escape.txt", "gotcha"}});
  EXPECT_THAT(OpenError(dotdot), AllOf(HasSubstr("dotdot.fmu: entry \"../escape.txt\""),
                                       HasSubstr("outside the FMU's folder")));
  EXPECT_FALSE(std::filesystem::exists(tmp_ / "escape.txt"));
  const std::filesystem::path absolute = MakeZip("absolute.fmu", {{"/tmp/escape.txt", "x"}});
  EXPECT_THAT(OpenError(absolute), HasSubstr("entry \"/tmp/escape.txt\" has an absolute path"));
  EXPECT_TRUE(NothingLeftBehind());
}

TEST(FmuArchive, SafeEntryNames) {
  EXPECT_TRUE(IsSafeEntryName("modelDescription.xml"));
  EXPECT_TRUE(IsSafeEntryName("binaries/linux64/lag.so"));
  EXPECT_TRUE(IsSafeEntryName("resources/..data"));
  EXPECT_TRUE(IsSafeEntryName("a../b"));
  EXPECT_FALSE(IsSafeEntryName(""));
  EXPECT_FALSE(IsSafeEntryName(".."));
  EXPECT_FALSE(IsSafeEntryName("../x"));
  EXPECT_FALSE(IsSafeEntryName("a/../../x"));
  EXPECT_FALSE(IsSafeEntryName("a/.."));
  EXPECT_FALSE(IsSafeEntryName("a\\..\\x"));
  EXPECT_FALSE(IsSafeEntryName("/etc/passwd"));
  EXPECT_FALSE(IsSafeEntryName("\\x"));
  EXPECT_FALSE(IsSafeEntryName("C:\\x"));
}

}  // namespace
}  // namespace hiltwin::fmi
