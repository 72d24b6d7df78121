// Every way an FMU is refused at open: a PlantError (exit 2 in the commands) whose message
// names the file, the entry or line, and the reason. A refused FMU leaves no folder behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zip.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
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
  // A zip with the given entries (name, content), made with libzip as a hostile tool would;
  // with `base`, a copy of that FMU with the entries added; `store`: not compressed.
  [[nodiscard]] std::filesystem::path MakeZip(
      const std::string& name, const std::vector<std::pair<std::string, std::string>>& entries,
      const std::filesystem::path& base = {}, bool store = false) {
    std::filesystem::path path = tmp_ / name;
    if (!base.empty()) std::filesystem::copy_file(base, path);
    int error = 0;
    zip_t* archive = zip_open(path.c_str(), base.empty() ? ZIP_CREATE | ZIP_TRUNCATE : 0, &error);
    EXPECT_NE(archive, nullptr);
    for (const auto& [entry, content] : entries) {
      zip_source_t* source = zip_source_buffer(archive, content.data(), content.size(), 0);
      const zip_int64_t index =
          zip_file_add(archive, entry.c_str(), source, ZIP_FL_ENC_UTF_8 | ZIP_FL_OVERWRITE);
      EXPECT_GE(index, 0) << entry;
      if (store) {
        EXPECT_EQ(zip_set_file_compression(archive, static_cast<zip_uint64_t>(index),
                                           ZIP_CM_STORE, 0),
                  0);
      }
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

// Other platforms' binaries are not unpacked, but the message still lists them.
TEST_F(FmuRefused, NoBinaryForThisPlatformListsTheOnesInTheArchive) {
  const std::filesystem::path fmu = MakeZip(
      "win.fmu", {{"binaries/win64/bad_no_binary.dll", "MZ"}, {"binaries/darwin64/x.dylib", ""}},
      TestFmu("bad_no_binary"));
  EXPECT_THAT(OpenError(fmu), HasSubstr("(binaries for: darwin64, win64)"));
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

// Only what running the FMU needs is unpacked: modelDescription.xml, this platform's binaries
// and resources/; documentation, sources, other platforms' binaries and the icon stay in the
// archive (a 1 MB FMU unpacked a 1 GiB entry of any name into $TMPDIR).
TEST_F(FmuRefused, OnlyTheDescriptionThisPlatformsBinariesAndResourcesAreUnpacked) {
  const std::filesystem::path fmu =
      MakeZip("extras.fmu",
              {{"documentation/index.html", "<html/>"},
               {"sources/lag_model.c", "int x;"},
               {"binaries/win64/lag.dll", "MZ"},
               {"model.png", "PNG"},
               {"resources/table.txt", "1 2 3"}},
              TestFmu("lag"));
  const std::unique_ptr<FmuPlant> plant = OpenFmu(fmu);
  const std::filesystem::path dir = plant->unpack_dir();
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path().lexically_relative(dir).string());
  }
  EXPECT_THAT(files, ::testing::UnorderedElementsAre(
                         "modelDescription.xml", "binaries/" HILTWIN_FMU_PLATFORM "/lag.so",
                         "resources/table.txt"));
}

// An archive of more entries than the cap is refused before anything is unpacked, naming the
// count and the cap.
TEST_F(FmuRefused, MoreEntriesThanTheCap) {
  std::vector<std::pair<std::string, std::string>> many;
  for (std::uint64_t i = 0; i < kMaxFmuEntries; ++i) {
    many.emplace_back("documentation/" + std::to_string(i) + ".txt", "");
  }
  const std::filesystem::path fmu = MakeZip("many.fmu", many, TestFmu("lag"));
  EXPECT_THAT(OpenError(fmu), HasSubstr("many.fmu: the archive has 10002 entries, more than the "
                                        "10000 hiltwin opens in an FMU"));
  EXPECT_TRUE(NothingLeftBehind());
}

// What is unpacked is capped in bytes: an entry past the cap is refused before it is written,
// naming the entry, its size and the cap (here a cap of 1 MiB and 2 MiB of zeros, which
// compress to 2 KiB; the default cap is 256 MiB).
TEST_F(FmuRefused, UnpackedBytesPastTheCap) {
  EXPECT_EQ(FmuUnpackLimits{}.max_bytes, std::uint64_t{256} << 20);
  EXPECT_EQ(FmuUnpackLimits{}.max_entries, 10000U);
  const std::string zeros(std::size_t{2} << 20, '\0');
  const std::filesystem::path fmu =
      MakeZip("big.fmu", {{"resources/zeros.bin", zeros}}, TestFmu("lag"));
  EXPECT_LT(std::filesystem::file_size(fmu), std::uintmax_t{1} << 20);
  std::string error;
  try {
    FmuOptions options;
    options.unpack_limits.max_bytes = std::uint64_t{1} << 20;
    (void)OpenFmu(fmu, std::move(options));
  } catch (const plant::PlantError& e) {
    error = e.what();
  }
  EXPECT_THAT(error, AllOf(HasSubstr("big.fmu: entry \"resources/zeros.bin\" (2097152 bytes) "
                                     "would unpack more than 1048576 bytes"),
                           HasSubstr("the most hiltwin unpacks from an FMU")));
  EXPECT_TRUE(NothingLeftBehind());
}

// A damaged entry names libzip's reason (a CRC error), not "damaged entry or disk full".
TEST_F(FmuRefused, ACorruptEntrySaysWhyLibzipRefusedIt) {
  const std::string text(4096, 'r');
  const std::filesystem::path fmu =
      MakeZip("crc.fmu", {{"resources/data.txt", text}}, TestFmu("lag"), true);
  // The entry is stored as it is; flip a byte in the middle of its data.
  zip_t* archive = zip_open(fmu.c_str(), ZIP_RDONLY, nullptr);
  ASSERT_NE(archive, nullptr);
  zip_stat_t st;
  zip_stat_init(&st);
  ASSERT_EQ(zip_stat(archive, "resources/data.txt", 0, &st), 0);
  zip_discard(archive);
  std::string bytes;
  {
    std::ifstream in(fmu, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The local header: 30 bytes, the name, the extra field, then the data.
  const std::size_t header = bytes.find("resources/data.txt") - 30;
  ASSERT_EQ(bytes.compare(header, 4, "PK\x03\x04"), 0);
  const auto u16 = [&bytes](std::size_t at) {
    return static_cast<std::size_t>(static_cast<unsigned char>(bytes[at])) |
           static_cast<std::size_t>(static_cast<unsigned char>(bytes[at + 1])) << 8U;
  };
  const std::size_t middle = header + 30 + u16(header + 26) + u16(header + 28) + st.comp_size / 2;
  bytes[middle] = static_cast<char>(bytes[middle] ^ 0x55);
  std::ofstream(fmu, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_THAT(OpenError(fmu), AllOf(HasSubstr("crc.fmu: entry \"resources/data.txt\""),
                                    HasSubstr("(libzip says: CRC error)"),
                                    HasSubstr("export it again")));
  EXPECT_TRUE(NothingLeftBehind());
}

// lag.fmu's modelDescription.xml with `from` replaced by `to`.
std::string LagDescriptionWith(const std::string& from, const std::string& to) {
  std::ifstream in(std::filesystem::path(HILTWIN_TEST_FMU_DIR) / "stage/lag/modelDescription.xml");
  std::string xml(std::istreambuf_iterator<char>(in), {});
  const std::size_t at = xml.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? xml : xml.replace(at, from.size(), to);
}

// ModelStructure refers to variables by their 1-based index in ModelVariables: an index past
// the last variable (or not a number, or a dependency past it, or an output that is not one)
// is refused with its line, as a file that does not describe the binary (it ran before).
TEST_F(FmuRefused, DanglingModelStructureIndicesAreRefusedWithTheirLine) {
  const auto error_with = [this](const std::string& name, const std::string& to) {
    const std::string xml = LagDescriptionWith("<Unknown index=\"2\"/>", to);
    return OpenError(MakeZip(name, {{"modelDescription.xml", xml}}, TestFmu("lag")));
  };
  EXPECT_THAT(error_with("past.fmu", "<Unknown index=\"7\"/>"),
              AllOf(HasSubstr("past.fmu: modelDescription.xml:28: <Outputs> <Unknown index=\"7\">"
                              " refers to variable 7, but <ModelVariables> declares 5"),
                    HasSubstr("export the FMU again")));
  EXPECT_THAT(error_with("zero.fmu", "<Unknown index=\"0\"/>"),
              HasSubstr("<Unknown index=\"0\"> refers to variable 0, but <ModelVariables>"));
  EXPECT_THAT(error_with("text.fmu", "<Unknown index=\"two\"/>"),
              HasSubstr("<Unknown index=\"two\">: \"two\" is not a variable's index (1 to 5)"));
  EXPECT_THAT(error_with("deps.fmu", "<Unknown index=\"2\" dependencies=\"1 9\"/>"),
              HasSubstr("<Outputs> <Unknown index=\"2\"> dependencies=\"1 9\" refers to "
                        "variable 9, but <ModelVariables> declares 5"));
  EXPECT_THAT(error_with("input.fmu", "<Unknown index=\"1\"/>"),
              HasSubstr("<Outputs> <Unknown index=\"1\"> refers to variable 1 \"u\", whose "
                        "causality is \"input\", not \"output\""));
  const std::string derivative =
      LagDescriptionWith("<Real start=\"0\" unit=\"rad\"/>",
                         "<Real start=\"0\" unit=\"rad\" derivative=\"6\"/>");
  EXPECT_THAT(OpenError(MakeZip("der.fmu", {{"modelDescription.xml", derivative}}, TestFmu("lag"))),
              HasSubstr("<Real derivative=\"6\"> refers to variable 6, but <ModelVariables> "
                        "declares 5"));
  EXPECT_TRUE(NothingLeftBehind());
}

// A name that is a variable of another causality is explained with the right article.
TEST_F(FmuRefused, NonPortsAreExplainedByTheirCausality) {
  const std::string xml = LagDescriptionWith(
      "  </ModelVariables>",
      "    <ScalarVariable name=\"time\" valueReference=\"8\" causality=\"independent\">"
      "<Real/></ScalarVariable>\n"
      "    <ScalarVariable name=\"energy\" valueReference=\"9\"><Real/></ScalarVariable>\n"
      "  </ModelVariables>");
  const auto plant = OpenFmu(MakeZip("vars.fmu", {{"modelDescription.xml", xml}}, TestFmu("lag")));
  EXPECT_EQ(plant->ExplainNonPort("time"),
            "is the independent variable of vars.fmu (causality \"independent\"); only inputs "
            "can be driven and outputs followed");
  EXPECT_EQ(plant->ExplainNonPort("energy"),
            "is a local variable of vars.fmu (causality \"local\"); only inputs can be driven "
            "and outputs followed");
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
