// The completion tree of the real `hiltwin` command line: every command and option the parser
// knows is offered, every offered value is one the parser accepts, and values complete by kind
// (fixed set, file, directory, nothing). Small apps cover the shapes hiltwin does not use yet:
// nested commands, hidden ones, option groups, values a shell word cannot hold.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bash_completion.h"
#include "cli_app.h"

namespace {

using hiltwin::app::BashCompletionScript;
using hiltwin::app::BuildCliApp;
using hiltwin::app::CommandCompletion;
using hiltwin::app::CompletionTree;
using hiltwin::app::OptionCompletion;
using hiltwin::app::ValueKind;
using Strings = std::vector<std::string>;

const CommandCompletion* FindCommand(const std::vector<CommandCompletion>& tree,
                                     const std::string& path) {
  for (const auto& command : tree) {
    if (command.path == path) return &command;
  }
  ADD_FAILURE() << "no command '" << path << "' in the completion tree";
  return nullptr;
}

const OptionCompletion* FindOption(const CommandCompletion& command, const std::string& name) {
  for (const auto& option : command.options) {
    for (const auto& known : option.names) {
      if (known == name) return &option;
    }
  }
  return nullptr;
}

Strings Words(const std::string& text) {
  std::istringstream in(text);
  Strings words;
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

// Parses `words` with a fresh app; true unless a value check (IsMember and the like) refuses.
// Other parse errors (a required command missing after a root option) do not concern values.
bool ValueAccepted(const Strings& words) {
  const auto cli = BuildCliApp();
  std::vector<const char*> argv;
  for (const auto& word : words) argv.push_back(word.c_str());
  try {
    cli->app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ValidationError&) {
    return false;
  } catch (const CLI::ParseError&) {
  }
  return true;
}

TEST(CompletionTree, OffersEveryRegisteredCommandInHelpOrder) {
  const auto cli = BuildCliApp();
  const auto tree = CompletionTree(cli->app);
  Strings registered;
  for (const auto& command : cli->commands) registered.push_back(command.app->get_name());
  ASSERT_EQ(cli->commands.size(), hiltwin::app::CommandRegistry().size());
  EXPECT_EQ(tree.front().path, "hiltwin");
  EXPECT_EQ(tree.front().subcommands, registered);
  EXPECT_EQ(registered.back(), "completion");  // last in --help: a convenience
  for (const auto& name : registered) FindCommand(tree, "hiltwin " + name);
}

TEST(CompletionTree, OffersEveryOptionOfEveryCommand) {
  const auto cli = BuildCliApp();
  const auto tree = CompletionTree(cli->app);
  for (const auto& command : cli->commands) {
    const auto* node = FindCommand(tree, "hiltwin " + command.app->get_name());
    ASSERT_NE(node, nullptr);
    for (const CLI::Option* option : command.app->get_options()) {
      for (const auto& name : option->get_lnames()) {
        EXPECT_NE(FindOption(*node, "--" + name), nullptr) << node->path << " --" << name;
      }
      for (const auto& name : option->get_snames()) {
        EXPECT_NE(FindOption(*node, "-" + name), nullptr) << node->path << " -" << name;
      }
    }
  }
}

TEST(CompletionTree, RunClockOffersItsTwoClocks) {
  const auto cli = BuildCliApp();
  const auto tree = CompletionTree(cli->app);
  const auto* clock = FindOption(*FindCommand(tree, "hiltwin run"), "--clock");
  ASSERT_NE(clock, nullptr);
  EXPECT_EQ(clock->value.kind, ValueKind::kChoices);
  EXPECT_EQ(clock->value.choices, (Strings{"realtime", "virtual"}));
}

// Every fixed set of values in the tree, each with the words that lead to it: "hiltwin run
// --clock", or "hiltwin completion" for a positional argument.
std::vector<std::pair<Strings, Strings>> ChoiceSets(const std::vector<CommandCompletion>& tree) {
  std::vector<std::pair<Strings, Strings>> sets;
  for (const auto& command : tree) {
    for (const auto& option : command.options) {
      if (option.value.kind != ValueKind::kChoices) continue;
      auto words = Words(command.path);
      words.push_back(option.names.back());
      sets.emplace_back(words, option.value.choices);
    }
    if (command.positional.kind == ValueKind::kChoices) {
      sets.emplace_back(Words(command.path), command.positional.choices);
    }
  }
  return sets;
}

TEST(CompletionTree, EveryOfferedValueIsOneTheParserAccepts) {
  const auto cli = BuildCliApp();
  int checked = 0;
  for (auto [words, choices] : ChoiceSets(CompletionTree(cli->app))) {
    EXPECT_FALSE(choices.empty()) << ::testing::PrintToString(words);
    for (const auto& choice : choices) {
      words.push_back(choice);
      EXPECT_TRUE(ValueAccepted(words)) << ::testing::PrintToString(words);
      words.pop_back();
      ++checked;
    }
    // The check must bite, or the loop above proves nothing.
    words.push_back("no-such-choice");
    EXPECT_FALSE(ValueAccepted(words)) << ::testing::PrintToString(words);
  }
  EXPECT_GT(checked, 10);  // --log-level alone has six
}

TEST(CompletionTree, ValuesCompleteByKind) {
  const auto cli = BuildCliApp();
  const auto tree = CompletionTree(cli->app);
  const auto& run = *FindCommand(tree, "hiltwin run");
  const auto kind = [](const CommandCompletion& command, const std::string& name) {
    const auto* option = FindOption(command, name);
    EXPECT_NE(option, nullptr) << command.path << " " << name;
    return option == nullptr ? ValueKind::kNoValue : option->value.kind;
  };
  EXPECT_EQ(kind(run, "--log"), ValueKind::kFile);
  EXPECT_EQ(kind(run, "--config"), ValueKind::kFile);
  EXPECT_EQ(kind(run, "--rate"), ValueKind::kNone);  // a number: nothing to offer
  EXPECT_EQ(kind(run, "--no-progress"), ValueKind::kNoValue);
  EXPECT_EQ(kind(*FindCommand(tree, "hiltwin doctor"), "--root"), ValueKind::kDirectory);
  EXPECT_EQ(FindCommand(tree, "hiltwin assess")->positional.kind, ValueKind::kFile);
  const auto& completion = *FindCommand(tree, "hiltwin completion");
  EXPECT_EQ(completion.positional.choices, Strings{"bash"});
  EXPECT_EQ(kind(completion, "--output"), ValueKind::kFile);
  EXPECT_EQ(run.positional.kind, ValueKind::kNoValue);
}

TEST(CompletionTree, RootOptionsCompleteAfterACommandTheyFallThroughTo) {
  const auto cli = BuildCliApp();
  const auto tree = CompletionTree(cli->app);
  const auto& run = *FindCommand(tree, "hiltwin run");
  const auto* log_level = FindOption(run, "--log-level");
  ASSERT_NE(log_level, nullptr);
  EXPECT_EQ(log_level->value.choices, FindOption(tree.front(), "--log-level")->value.choices);
  int helps = 0;
  for (const auto& option : run.options) {
    for (const auto& name : option.names) helps += name == "--help";
  }
  EXPECT_EQ(helps, 1);  // run's own --help shadows the root's
}

TEST(CompletionTree, NestedCommandsWithHiddenOnesLeftOut) {
  CLI::App tool{"a tool", "tool"};
  std::string mode, level, dir, secret, grouped;
  CLI::App* remote = tool.add_subcommand("remote", "remotes");
  CLI::App* add = remote->add_subcommand("add", "add one");
  add->add_option("--mode", mode)->check(CLI::IsMember({"fast", "two words", "$(x)"}));
  add->add_option("--level", level)
      ->transform(CLI::Transformer(std::map<std::string, std::string>{{"low", "1"}}));
  remote->add_subcommand("rm", "remove one");
  remote->add_option("--dir", dir)->check(CLI::ExistingDirectory);
  remote->add_option("--secret", secret)->group("");
  remote->add_option_group("extra")->add_option("--grouped", grouped);
  tool.add_subcommand("hidden", "not shown")->group("");

  const auto tree = CompletionTree(tool);
  Strings paths;
  for (const auto& command : tree) paths.push_back(command.path);
  EXPECT_EQ(paths, (Strings{"tool", "tool remote", "tool remote add", "tool remote rm"}));
  EXPECT_EQ(tree[1].subcommands, (Strings{"add", "rm"}));
  EXPECT_EQ(FindOption(tree[1], "--dir")->value.kind, ValueKind::kDirectory);
  EXPECT_EQ(FindOption(tree[1], "--secret"), nullptr);
  EXPECT_NE(FindOption(tree[1], "--grouped"), nullptr);
  // A value a shell word cannot hold as itself is left out rather than offered broken.
  EXPECT_EQ(FindOption(tree[2], "--mode")->value.choices, Strings{"fast"});
  EXPECT_EQ(FindOption(tree[2], "--level")->value.choices, Strings{"low"});  // a map's keys
}

TEST(BashCompletionScript, RegistersItsFunctionAndListsTheCommands) {
  const auto cli = BuildCliApp();
  const std::string script = BashCompletionScript(cli->app);
  std::string commands;
  for (const auto& command : cli->commands) commands += " " + command.app->get_name();
  // The header line cmake/GenerateManPage.cmake reads the commands from.
  EXPECT_NE(script.find("\n# Commands:" + commands + "\n"), std::string::npos) << script;
  EXPECT_NE(script.find("\ncomplete -F _hiltwin 'hiltwin'\n"), std::string::npos);
  EXPECT_NE(script.find("'hiltwin run --clock') echo 'words realtime virtual' ;;"),
            std::string::npos);
  CLI::App other{"", "my-tool"};
  EXPECT_NE(BashCompletionScript(other).find("complete -F _my_tool 'my-tool'"), std::string::npos);
}

}  // namespace
