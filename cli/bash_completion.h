#pragma once
// Shell completion generated from the CLI11 app itself (`hiltwin completion bash`), so the
// script offers exactly the commands, options and values the parser accepts and cannot drift
// from them. Read through CLI11's public getters only, so it works on any app, not just ours.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace hiltwin::app {

/// What the word after an option (or a positional argument) completes to.
enum class ValueKind {
  kNoValue,    ///< a flag (or a command without positional arguments): nothing follows
  kNone,       ///< a value with nothing to offer (a number, say)
  kChoices,    ///< one of a fixed set (CLI::IsMember)
  kFile,       ///< a file name: the path validators, and any free text (it may be a path)
  kDirectory,  ///< a directory name (CLI::ExistingDirectory)
};

struct ValueCompletion {
  ValueKind kind = ValueKind::kNoValue;
  std::vector<std::string> choices;  ///< for kChoices, in the validator's order
};

struct OptionCompletion {
  std::vector<std::string> names;  ///< with dashes: "-h", "--help"
  ValueCompletion value;
};

/// One command of the tree, the root included.
struct CommandCompletion {
  std::string path;                       ///< the words that select it: "hiltwin run"
  std::vector<std::string> subcommands;   ///< in `--help` order
  std::vector<OptionCompletion> options;  ///< its own, then those it falls through to
  ValueCompletion positional;             ///< its first positional argument
};

/// The shown commands (hidden and disabled ones left out) of `app`, depth first from the root.
[[nodiscard]] std::vector<CommandCompletion> CompletionTree(const CLI::App& app);

/// How `option`'s value completes, read from its CLI11 type name (see the .cpp).
[[nodiscard]] ValueCompletion CompletionOfValue(const CLI::Option& option);

/// A self-contained bash completion script for `app` (no bash-completion package needed).
/// Its header line "# Commands: A B ..." lists the root's subcommands for other tools
/// (cmake/GenerateManPage.cmake builds one man page section per command from it).
[[nodiscard]] std::string BashCompletionScript(const CLI::App& app);

}  // namespace hiltwin::app
