// `hiltwin --version` names the project version and, in a git checkout, the commit the binary
// was built from (cmake/WriteVersionSource.cmake runs `git describe` at every build).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace test = hiltwin::test;

TEST(VersionCli, NamesTheProjectVersionAndTheCommitItWasBuiltFrom) {
  const auto r = test::Run({HILTWIN_BINARY, "--version"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string prefix = "hiltwin " HILTWIN_PROJECT_VERSION " (";
  ASSERT_EQ(r.out.rfind(prefix, 0), 0U) << r.out;
  if (!std::filesystem::exists(std::filesystem::path(HILTWIN_SOURCE_DIR) / ".git")) {
    EXPECT_NE(r.out.find("(not built from a git checkout)"), std::string::npos) << r.out;
    return;
  }
  // "(git v0.1.0-3-g1a2b3c4d5e)", "(git 1a2b3c4d5e-dirty)": what git says of HEAD now, the
  // dirty mark aside (a file edited since the build is no reason to fail).
  // Read without std::regex, whose inlined std::function trips g++ 12's -Wmaybe-uninitialized
  // in the ASan build (-Werror).
  const std::string marker = "(git ";
  const auto open = r.out.rfind(marker);
  ASSERT_NE(open, std::string::npos) << r.out;
  const auto close = r.out.find(')', open);
  ASSERT_EQ(r.out.substr(close == std::string::npos ? r.out.size() : close), ")\n") << r.out;
  const std::string built = r.out.substr(open + marker.size(), close - open - marker.size());
  const auto now =
      test::Run({"git", "-C", HILTWIN_SOURCE_DIR, "describe", "--tags", "--always", "--abbrev=10"});
  if (now.exit_code != 0) GTEST_SKIP() << "git cannot read the checkout here: " << now.err;
  const std::string head = now.out.substr(0, now.out.find('\n'));
  EXPECT_EQ(built.rfind(head, 0), 0U)
      << "built from " << built << ", HEAD is " << head << " (rebuild after a commit)";
}

}  // namespace
