// The bash completion script of a CLI11 app (bash_completion.h): the tree of commands, options
// and values read from the app, written as three lookup functions in front of one fixed
// completion function.
#include "bash_completion.h"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <string_view>

namespace hiltwin::app {
namespace {

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::istringstream in(text);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

// compgen -W splits its word list at blanks and expands it like a command line, so a value
// with a blank or a shell character could not be offered as itself: it is left out.
bool IsPlainWord(const std::string& word) {
  return !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
           std::string_view("-_.:+/@%=,").find(c) != std::string_view::npos;
  });
}

// "{a,b,c}" (IsMember) or "{a->1,b->2}" (a Transformer's map, whose keys are the input).
std::vector<std::string> ChoicesOf(const std::string& set) {
  std::vector<std::string> choices;
  for (std::string item : Split(set, ',')) {
    item = item.substr(0, item.find("->"));
    if (IsPlainWord(item)) choices.push_back(item);
  }
  return choices;
}

bool IsShown(const CLI::Option* option) { return !option->get_group().empty(); }
bool IsShownCommand(const CLI::App* app) {
  return !app->get_name().empty() && !app->get_group().empty() && !app->get_disabled();
}
bool IsOptionGroup(const CLI::App* app) { return app->get_name().empty(); }

std::vector<std::string> NamesOf(const CLI::Option& option) {
  std::vector<std::string> names;
  for (const auto& name : option.get_snames()) names.push_back("-" + name);
  for (const auto& name : option.get_lnames()) names.push_back("--" + name);
  return names;
}

// The named options the app parses itself: its own and those of its option groups (CLI11
// keeps a group as an unnamed subcommand).
std::vector<OptionCompletion> OwnOptions(const CLI::App& app) {
  std::vector<OptionCompletion> options;
  for (const CLI::Option* option : app.get_options(IsShown)) {
    if (option->nonpositional()) options.push_back({NamesOf(*option), CompletionOfValue(*option)});
  }
  for (const CLI::App* group : app.get_subcommands(IsOptionGroup)) {
    const auto grouped = OwnOptions(*group);
    options.insert(options.end(), grouped.begin(), grouped.end());
  }
  return options;
}

bool SharesAName(const std::vector<OptionCompletion>& options, const OptionCompletion& option) {
  return std::any_of(options.begin(), options.end(), [&option](const OptionCompletion& known) {
    return std::find_first_of(known.names.begin(), known.names.end(), option.names.begin(),
                              option.names.end()) != known.names.end();
  });
}

// With fallthrough, an option the command does not know goes to its parent (`hiltwin run
// --log-level debug`), so the parent's options complete there too, unless shadowed (--help).
std::vector<OptionCompletion> OptionsOf(const CLI::App& app) {
  auto options = OwnOptions(app);
  if (app.get_fallthrough() && app.get_parent() != nullptr) {
    for (const auto& inherited : OptionsOf(*app.get_parent())) {
      if (!SharesAName(options, inherited)) options.push_back(inherited);
    }
  }
  return options;
}

ValueCompletion PositionalOf(const CLI::App& app) {
  const auto positionals =
      app.get_options([](const CLI::Option* option) { return option->get_positional(); });
  return positionals.empty() ? ValueCompletion{} : CompletionOfValue(*positionals.front());
}

void AddCommand(const CLI::App& app, const std::string& path,
                std::vector<CommandCompletion>& tree) {
  const auto subcommands = app.get_subcommands(IsShownCommand);
  CommandCompletion command{path, {}, OptionsOf(app), PositionalOf(app)};
  for (const CLI::App* sub : subcommands) command.subcommands.push_back(sub->get_name());
  tree.push_back(std::move(command));
  for (const CLI::App* sub : subcommands) AddCommand(*sub, path + " " + sub->get_name(), tree);
}

std::string Join(const std::vector<std::string>& words) {
  std::string joined;
  for (const auto& word : words) joined += (joined.empty() ? "" : " ") + word;
  return joined;
}

// What the script's lookup prints for a value: "words W...", "file", "dir", "none", or
// nothing for no value at all.
std::string ValueWords(const ValueCompletion& value) {
  switch (value.kind) {
    case ValueKind::kNoValue:
      return "";
    case ValueKind::kNone:
      return "none";
    case ValueKind::kChoices:
      return "words " + Join(value.choices);
    case ValueKind::kFile:
      return "file";
    case ValueKind::kDirectory:
      return "dir";
  }
  return "";
}

// Single quotes keep every character but the quote itself, which is closed around \'.
std::string Quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

using CaseEntries = std::vector<std::pair<std::string, std::string>>;

// A lookup function: `case $1` over the keys, each printing its text.
std::string CaseFunction(const std::string& name, const std::string& comment,
                         const CaseEntries& entries) {
  std::string text = "# " + comment + "\n" + name + "() {\n  case $1 in\n";
  for (const auto& [key, output] : entries) {
    text += "    " + Quote(key) + ") echo " + Quote(output) + " ;;\n";
  }
  return text + "  esac\n}\n\n";
}

// Keys: "PATH OPTION" for an option's value, "PATH" alone for the positional argument.
CaseEntries ValueEntries(const std::vector<CommandCompletion>& tree) {
  CaseEntries entries;
  for (const auto& command : tree) {
    for (const auto& option : command.options) {
      const std::string words = ValueWords(option.value);
      if (words.empty()) continue;
      for (const auto& name : option.names) entries.emplace_back(command.path + " " + name, words);
    }
    if (command.positional.kind != ValueKind::kNoValue) {
      entries.emplace_back(command.path, ValueWords(command.positional));
    }
  }
  return entries;
}

std::string LookupFunctions(const std::string& prefix, const std::vector<CommandCompletion>& tree) {
  CaseEntries commands;
  CaseEntries options;
  for (const auto& command : tree) {
    if (!command.subcommands.empty()) {
      commands.emplace_back(command.path, Join(command.subcommands));
    }
    std::vector<std::string> names;
    for (const auto& option : command.options) {
      names.insert(names.end(), option.names.begin(), option.names.end());
    }
    options.emplace_back(command.path, Join(names));
  }
  return CaseFunction(prefix + "_commands", "The subcommands of a command path.", commands) +
         CaseFunction(prefix + "_options", "The options valid after a command path.", options) +
         CaseFunction(prefix + "_value",
                      "What follows \"PATH OPTION\" (nothing: a flag) or a positional argument "
                      "of \"PATH\":\n# words W..., file, dir or none.",
                      ValueEntries(tree));
}

// The fixed part: finds the command path typed so far, then completes the current word from
// the lookups. @p@ is the function prefix, @name@ the program.
constexpr std::string_view kCompletionFunction = R"bash(# Adds to COMPREPLY the candidates for
# the word $2 given $1: "words W...", "file", "dir" or "none" (a value with nothing to offer).
@p@_reply() {
  local -a found=()
  case $1 in
    words\ *) mapfile -t found < <(compgen -W "${1#words }" -- "$2") ;;
    file) compopt -o filenames 2>/dev/null; mapfile -t found < <(compgen -f -- "$2") ;;
    dir) compopt -o filenames 2>/dev/null; mapfile -t found < <(compgen -d -- "$2") ;;
  esac
  COMPREPLY+=("${found[@]}")
}

@p@() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} path=@name@ i word
  COMPREPLY=()
  # --option=VALUE: bash splits the word at '=' (COMP_WORDBREAKS).
  if [[ $cur == = ]]; then
    cur=
  elif [[ $prev == = ]]; then
    prev=${COMP_WORDS[COMP_CWORD-2]}
  fi
  # The command path: a subcommand's name descends into it; an option's value is skipped, so
  # a value that is also a command's name (--log-level trace) is not taken for the command.
  for ((i = 1; i < COMP_CWORD; i++)); do
    word=${COMP_WORDS[i]}
    if [[ $word == -* && -n $(@p@_value "$path $word") ]]; then
      if [[ ${COMP_WORDS[i+1]} == = ]]; then ((i++)); fi
      ((i++))
    elif [[ " $(@p@_commands "$path") " == *" $word "* ]]; then
      path+=" $word"
    fi
  done
  local value=
  if [[ $prev == -* ]]; then value=$(@p@_value "$path $prev"); fi
  if [[ -n $value ]]; then
    @p@_reply "$value" "$cur"
  elif [[ $cur == -* ]]; then
    @p@_reply "words $(@p@_options "$path")" "$cur"
  else
    @p@_reply "words $(@p@_commands "$path")" "$cur"
    @p@_reply "$(@p@_value "$path")" "$cur"
  fi
}
complete -F @p@ @name@
)bash";

std::string ReplaceAll(std::string text, std::string_view from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// A shell function name from the program's: "_hiltwin"; other characters become '_'.
std::string FunctionPrefix(const std::string& program) {
  std::string prefix = "_";
  for (const char c : program) {
    prefix += std::isalnum(static_cast<unsigned char>(c)) != 0 ? c : '_';
  }
  return prefix;
}

}  // namespace

// CLI11 names an option's value by its type, then ':' and the description of each validator:
// "TEXT:{realtime,virtual}" (IsMember), "TEXT:FILE" (ExistingFile), "TEXT:DIR"
// (ExistingDirectory), "TEXT:PATH(existing)", "INT:INT in [0 - 10000]" (Range). CLI11 2.1
// gives no const access to the validators themselves, so this name is the interface read.
ValueCompletion CompletionOfValue(const CLI::Option& option) {
  if (option.get_items_expected_max() == 0) return {};
  const std::string type = option.get_type_name();
  const auto open = type.find(":{");
  if (open != std::string::npos) {
    const auto close = type.find('}', open);
    return {ValueKind::kChoices, ChoicesOf(type.substr(open + 2, close - open - 2))};
  }
  const auto parts = Split(type, ':');
  const auto has = [&parts](std::string_view wanted) {
    return std::any_of(parts.begin(), parts.end(),
                       [wanted](const std::string& part) { return part.rfind(wanted, 0) == 0; });
  };
  if (has("DIR")) return {ValueKind::kDirectory, {}};
  // Free text may well be a path (the CLI has no path type): offer file names, as bash does
  // for a command it knows nothing about.
  if (has("FILE") || has("PATH") || (!parts.empty() && parts.front() == "TEXT")) {
    return {ValueKind::kFile, {}};
  }
  return {ValueKind::kNone, {}};
}

std::vector<CommandCompletion> CompletionTree(const CLI::App& app) {
  std::vector<CommandCompletion> tree;
  AddCommand(app, app.get_name(), tree);
  return tree;
}

std::string BashCompletionScript(const CLI::App& app) {
  const auto tree = CompletionTree(app);
  const std::string& program = app.get_name();
  const std::string prefix = FunctionPrefix(program);
  std::string script = "# bash completion for " + program + ", generated by `" + program +
                       " completion bash`: regenerate, do not edit.\n";
  script += "# Load it with `source FILE`, or install it as share/bash-completion/completions/" +
            program + ".\n";
  script += "# Commands: " + Join(tree.front().subcommands) + "\n\n";
  script += LookupFunctions(prefix, tree);
  script += ReplaceAll(ReplaceAll(std::string(kCompletionFunction), "@p@", prefix), "@name@",
                       Quote(program));
  return script;
}

}  // namespace hiltwin::app
