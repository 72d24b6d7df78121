// The command registry and the one CLI11 app all subcommands hang from (cli_app.h).
#include "cli_app.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <sstream>
#include <string>

#include "version.h"

namespace hiltwin::app {
namespace {

/// `hiltwin --help` lists each command on one line, the first of its description; the rest of
/// the paragraph is the command's own --help (a list of nine paragraphs hid the list).
class OneLinePerCommand : public CLI::Formatter {
 public:
  std::string make_subcommand(const CLI::App* sub) const override {
    const std::string& description = sub->get_description();
    std::ostringstream out;
    CLI::detail::format_help(out, sub->get_display_name(true),
                             description.substr(0, description.find('\n')), column_width_);
    return out.str();
  }
};

}  // namespace

std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;  // function-local: safe during static init
  return registry;
}

bool RegisterCommand(int order, CommandFactory factory) {
  CommandRegistry().push_back({order, factory});
  return true;
}

CliApp::CliApp()
    : app{"hiltwin: a real-time Hardware-in-the-Loop runtime for digital twins.\n"
          "Runs a plant model behind the plant's own electrical interface, checks every deadline\n"
          "and tells you whether a run can be trusted.",
          "hiltwin"} {}

std::unique_ptr<CliApp> BuildCliApp() {
  auto cli = std::make_unique<CliApp>();
  CLI::App& app = cli->app;
  app.require_subcommand(1);
  app.fallthrough();  // --log-level may also follow the command
  app.set_version_flag("--version", kVersionText);
  app.footer("Run 'hiltwin <command> --help' for what one command does and its flags.");
  app.formatter(std::make_shared<OneLinePerCommand>());

  std::string& log_level = cli->log_level;
  app.add_option("--log-level", log_level,
                 "how much the non-real-time messages say: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  app.parse_complete_callback(
      [&log_level] { spdlog::set_level(spdlog::level::from_str(log_level)); });

  auto entries = CommandRegistry();
  std::stable_sort(entries.begin(), entries.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  for (const auto& entry : entries) cli->commands.push_back(entry.factory(app));
  return cli;
}

}  // namespace hiltwin::app
