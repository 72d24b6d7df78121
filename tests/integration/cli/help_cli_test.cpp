// `hiltwin --help` is a list: one line per command, its first; each command's own --help keeps
// the whole paragraph (cli/cli_app.cpp, OneLinePerCommand).
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "fakes/process.h"

namespace {

namespace test = hiltwin::test;

/// The lines between "Subcommands:" and the next blank line.
std::vector<std::string> CommandLines(const std::string& help) {
  std::istringstream in(help.substr(help.find("Subcommands:\n") + 13));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line) && !line.empty();) lines.push_back(line);
  return lines;
}

TEST(HelpCli, TheTopLevelHelpListsEachCommandOnOneLine) {
  const auto r = test::Run({HILTWIN_BINARY, "--help"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_NE(r.out.find("Subcommands:\n"), std::string::npos) << r.out;
  const std::vector<std::string> expected = {"run",     "ecs",    "hil",    "test",    "trace",
                                             "tune",    "monitor", "assess", "doctor", "io-test",
                                             "completion"};
  const std::vector<std::string> lines = CommandLines(r.out);
  ASSERT_EQ(lines.size(), expected.size()) << r.out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines[i].rfind("  " + expected[i] + " ", 0), 0U) << lines[i];
    EXPECT_LE(lines[i].size(), 130U) << lines[i];  // a line a terminal shows whole
  }
}

TEST(HelpCli, ACommandsOwnHelpKeepsItsWholeDescription) {
  const auto top = test::Run({HILTWIN_BINARY, "--help"});
  const auto own = test::Run({HILTWIN_BINARY, "io-test", "--help"});
  ASSERT_EQ(own.exit_code, 0) << own.err;
  // The thesis's figure for the bring-up run is in the paragraph, not in the one-line list.
  EXPECT_NE(own.out.find("--frames 720000"), std::string::npos) << own.out;
  EXPECT_EQ(top.out.find("--frames 720000"), std::string::npos) << top.out;
}

}  // namespace
