// `hiltwin completion bash` end to end: the real binary writes the script, real bash (no
// bash-completion package, no terminal) sources it and completes command lines as a TAB would;
// a shell other than bash and an unwritable --output end with their exit codes. And the man
// page the build generated renders without a warning and covers every command.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;
using Strings = std::vector<std::string>;

// Sources the script ($1), enters the folder $2 and completes the remaining arguments as bash
// does on a TAB after the last one (COMP_* set as bash sets them), through the function the
// script registered for hiltwin; prints COMPREPLY one per line.
constexpr const char* kCompleteDriver = R"bash(
source "$1" || exit 90
cd "$2" || exit 91
shift 2
COMP_WORDS=("$@")
COMP_CWORD=$((${#COMP_WORDS[@]} - 1))
COMP_LINE="${COMP_WORDS[*]}"
COMP_POINT=${#COMP_LINE}
spec=$(complete -p hiltwin) || exit 92
function=${spec##*-F }
function=${function%% *}
"$function" hiltwin "${COMP_WORDS[COMP_CWORD]}" "${COMP_WORDS[COMP_CWORD-1]}" || exit 93
printf '%s\n' "${COMPREPLY[@]}"
)bash";

Strings SortedLines(const std::string& text) {
  Strings lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  std::sort(lines.begin(), lines.end());
  return lines;
}

// The commands `hiltwin --help` lists: the names under "Subcommands:" (the continuation lines
// of their descriptions are indented further).
Strings HelpCommands() {
  const auto help = hiltwin::test::Run({HILTWIN_BINARY, "--help"});
  EXPECT_EQ(help.exit_code, 0) << help.err;
  Strings commands;
  std::istringstream in(help.out);
  std::string line;
  while (std::getline(in, line) && line != "Subcommands:") {
  }
  while (std::getline(in, line) && !line.empty()) {
    if (line.size() > 2 && line.compare(0, 2, "  ") == 0 && line[2] != ' ') {
      commands.push_back(line.substr(2, line.find(' ', 2) - 2));
    }
  }
  return commands;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class CompletionCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ =
        fs::temp_directory_path() / ("hiltwin_completion_" + std::to_string(getpid()) + "_" + test);
    fs::create_directories(dir_ / "cwd" / "logs");
    std::ofstream(dir_ / "cwd" / "a.csv") << "t,left,right\n";
    std::ofstream(dir_ / "cwd" / "b.csv") << "t,left,right\n";
    script_ = dir_ / "hiltwin.bash";
    const auto r =
        hiltwin::test::Run({HILTWIN_BINARY, "completion", "bash", "--output", script_.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // What a TAB offers after `words`, the last being the word under the cursor; sorted.
  [[nodiscard]] Strings Complete(const Strings& words) const {
    Strings argv{"bash",          "--norc",     "--noprofile",    "-c",
                 kCompleteDriver, "completion", script_.string(), (dir_ / "cwd").string()};
    argv.insert(argv.end(), words.begin(), words.end());
    const auto r = hiltwin::test::Run(argv);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "") << "completing " << ::testing::PrintToString(words);
    return SortedLines(r.out);
  }

  fs::path dir_;
  fs::path script_;
};

TEST_F(CompletionCli, PrintsTheScriptItWritesWithOutput) {
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "completion", "bash"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, ReadFile(script_));
}

TEST_F(CompletionCli, CompletesEveryCommand) {
  Strings commands = HelpCommands();
  ASSERT_GE(commands.size(), 8U);  // run ... completion: the parse above found the list
  std::sort(commands.begin(), commands.end());
  EXPECT_EQ(Complete({"hiltwin", ""}), commands);
  EXPECT_EQ(Complete({"hiltwin", "ru"}), Strings{"run"});
  EXPECT_EQ(Complete({"hiltwin", "completion", ""}), Strings{"bash"});
}

TEST_F(CompletionCli, CompletesOptionsAndTheirValues) {
  const Strings clocks{"realtime", "virtual"};
  EXPECT_EQ(Complete({"hiltwin", "run", "--cl"}), Strings{"--clock"});
  EXPECT_EQ(Complete({"hiltwin", "run", "--clock", ""}), clocks);
  // --clock=<TAB>: bash splits the word at '=' and the cursor sits on the '='.
  EXPECT_EQ(Complete({"hiltwin", "run", "--clock", "="}), clocks);
  EXPECT_EQ(Complete({"hiltwin", "run", "--clock", "=", "v"}), Strings{"virtual"});
  EXPECT_EQ(Complete({"hiltwin", "run", "--rate", ""}), Strings{});  // a number: nothing
  // --log-level falls through from the root; its value "trace" is no command here.
  EXPECT_EQ(Complete({"hiltwin", "run", "--log-level", "w"}), Strings{"warn"});
  EXPECT_EQ(Complete({"hiltwin", "--log-level", "trace", "r"}), Strings{"run"});
}

TEST_F(CompletionCli, CompletesPathsFromTheCurrentFolder) {
  EXPECT_EQ(Complete({"hiltwin", "run", "--log", ""}), (Strings{"a.csv", "b.csv", "logs"}));
  EXPECT_EQ(Complete({"hiltwin", "run", "--log", "a"}), Strings{"a.csv"});
  EXPECT_EQ(Complete({"hiltwin", "doctor", "--root", ""}), Strings{"logs"});
  EXPECT_EQ(Complete({"hiltwin", "assess", ""}), (Strings{"a.csv", "b.csv", "logs"}));
}

TEST_F(CompletionCli, AnyShellButBashIsBadUsage) {
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "completion", "zsh"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("'zsh'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bash only"), std::string::npos) << r.err;
}

TEST_F(CompletionCli, AnUnwritableOutputIsAnIoError) {
  const std::string path = (dir_ / "no-such-folder" / "hiltwin.bash").string();
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "completion", "bash", "--output", path});
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No such file or directory"), std::string::npos) << r.err;
}

TEST(ManPage, RendersWithoutWarningsAndCoversEveryCommand) {
  const std::string page = HILTWIN_MAN_PAGE;
  if (page.empty() || !fs::exists(page)) {
    GTEST_SKIP() << "no man page in this build (cross-compiled, or help2man missing)";
  }
  // -ww: every warning; -P-cbou: plain text, no overstriking, so the words can be searched.
  const auto r = hiltwin::test::Run({"groff", "-man", "-Tutf8", "-ww", "-P-cbou", page});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const auto& command : HelpCommands()) {
    EXPECT_NE(r.out.find("hiltwin " + command + "\n"), std::string::npos)
        << "no section for " << command;
  }
  const auto version = hiltwin::test::Run({HILTWIN_BINARY, "--version"});
  ASSERT_EQ(version.exit_code, 0) << version.err;
  const std::string text = version.out.substr(0, version.out.find('\n'));
  EXPECT_NE(r.out.find(text), std::string::npos) << "no '" << text << "' in the page";
}

}  // namespace
