// `hiltwin completion bash`: the bash completion script, generated from this very command line
// (bash_completion.h), so it completes exactly what the other commands accept.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bash_completion.h"
#include "commands.h"
#include "hiltwin/kernel_glue/os_calls.h"

namespace hiltwin::app {
namespace {

const std::vector<std::string> kShells = {"bash"};

struct CompletionOptions {
  std::string shell;
  std::string output;  ///< empty: stdout
};

// IsMember's description ("{bash}": the script reads it to complete the shell's name too),
// with an error that says what to do instead of CLI11's "zsh not in {bash}".
CLI::Validator KnownShell() {
  return {[](std::string& shell) -> std::string {
            if (std::find(kShells.begin(), kShells.end(), shell) != kShells.end()) return {};
            return "no completion script for the shell '" + shell +
                   "': hiltwin writes one for bash only; run 'hiltwin completion bash'";
          },
          CLI::IsMember(kShells).get_description()};
}

void WriteScript(const std::string& path, const std::string& script) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  int error = file == nullptr ? errno : 0;
  if (file != nullptr) {
    if (std::fputs(script.c_str(), file) == EOF) error = errno;
    if (std::fclose(file) != 0 && error == 0) error = errno;
  }
  if (error != 0) {
    throw CommandError(ExitCode::kIo, "--output " + path +
                                          ": cannot write the completion script (" +
                                          kernel_glue::ErrnoText(error) +
                                          "); choose a writable file, or leave --output out to "
                                          "print the script");
  }
}

int RunCompletion(const CompletionOptions& options, const CLI::App& root) {
  const std::string script = BashCompletionScript(root);
  if (options.output.empty()) {
    std::fputs(script.c_str(), stdout);
  } else {
    WriteScript(options.output, script);
  }
  return static_cast<int>(ExitCode::kPass);
}

Command AddCompletionCommand(CLI::App& parent) {
  auto options = std::make_shared<CompletionOptions>();
  CLI::App* app = parent.add_subcommand(
      "completion",
      "Print the shell completion script of hiltwin (bash), made from its commands and flags.");
  app->add_option("SHELL", options->shell, "the shell to complete in: bash")
      ->required()
      ->check(KnownShell());
  app->add_option("--output", options->output, "write the script to FILE instead of stdout")
      ->type_name("FILE");
  app->footer(
      "Try it in this shell:  source <(hiltwin completion bash)\n"
      "Keep it for your user: hiltwin completion bash --output "
      "~/.local/share/bash-completion/completions/hiltwin\n\n"
      "Exit code: 0 written; 2 for bad usage (a shell other than bash); 5 when --output cannot "
      "be written.");
  // The parent is complete when the command runs: every other command is in the script.
  const CLI::App* root = &parent;
  return Command{app, [options, root] { return RunCompletion(*options, *root); }};
}

}  // namespace

// Last in `hiltwin --help`: a convenience, not part of the HIL workflow.
HILTWIN_REGISTER_COMMAND(90, AddCompletionCommand);

}  // namespace hiltwin::app
