#include "hiltwin/runs/doctor_format.h"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <string_view>
#include <vector>

namespace hiltwin::app {
namespace {

using kernel_glue::CheckStatus;
using kernel_glue::ProbeCheck;
using kernel_glue::ProbeReport;

constexpr std::size_t kLineWidth = 100;

// Words of an advice text, with each `command in backticks` kept as one token so a wrapped
// line never splits a command the user will copy.
std::vector<std::string> AdviceTokens(std::string_view advice) {
  std::vector<std::string> tokens;
  bool in_command = false;
  std::istringstream words{std::string(advice)};
  for (std::string word; words >> word;) {
    if (in_command) {
      tokens.back() += ' ' + word;
    } else {
      tokens.push_back(word);
    }
    const auto ticks = std::count(word.begin(), word.end(), '`');
    if (ticks % 2 == 1) in_command = !in_command;
  }
  return tokens;
}

// "-> advice" under the value column, continued lines indented past the arrow.
std::string WrappedAdvice(std::string_view advice, std::size_t value_column) {
  const std::string indent(value_column, ' ');
  std::string out;
  std::string line = indent + "-> ";
  bool line_has_word = false;
  for (const auto& word : AdviceTokens(advice)) {
    if (line_has_word && line.size() + 1 + word.size() > kLineWidth) {
      out += line + "\n";
      line = indent + "   ";
      line_has_word = false;
    }
    if (line_has_word) line += ' ';
    line += word;
    line_has_word = true;
  }
  return out + line + "\n";
}

std::string Pad(std::string text, std::size_t width) {
  if (text.size() < width) text.append(width - text.size(), ' ');
  return text;
}

// "ok" stays quiet, anything else shouts (WARN, BAD) so it stands out in the column.
std::string StatusColumn(CheckStatus status) {
  std::string text(kernel_glue::ToString(status));
  if (status != CheckStatus::kOk) {
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  }
  return text;
}

}  // namespace

std::string DoctorAdvice(const ProbeCheck& check) {
  if (check.not_tried && check.advice.empty()) {
    return "run 'hiltwin doctor' without --no-try to try it for real (it is undone at once)";
  }
  return check.advice;
}

nlohmann::json DoctorJson(const ProbeReport& report) {
  nlohmann::json checks = nlohmann::json::array();
  for (const auto& check : report.checks) {
    checks.push_back({{"id", check.id},
                      {"name", check.name},
                      {"value", check.value},
                      {"status", kernel_glue::ToString(check.status)},
                      {"advice", DoctorAdvice(check)}});
  }
  return {{"checks", checks},
          {"summary",
           {{"ok", report.Count(CheckStatus::kOk)},
            {"warn", report.Count(CheckStatus::kWarn)},
            {"bad", report.Count(CheckStatus::kBad)}}}};
}

std::string DoctorText(const ProbeReport& report) {
  std::size_t name_width = 5;  // "CHECK"
  for (const auto& check : report.checks) name_width = std::max(name_width, check.name.size());
  const std::size_t status_width = 8;
  const std::size_t value_column = name_width + 2 + status_width;

  std::string out = Pad("CHECK", name_width + 2) + Pad("STATUS", status_width) + "VALUE\n";
  for (const auto& check : report.checks) {
    out += Pad(check.name, name_width + 2) + Pad(StatusColumn(check.status), status_width) +
           check.value + "\n";
    const std::string advice = DoctorAdvice(check);
    if (!advice.empty()) out += WrappedAdvice(advice, value_column);
  }
  out += "\n" + std::to_string(report.Count(CheckStatus::kOk)) + " ok, " +
         std::to_string(report.Count(CheckStatus::kWarn)) + " warn, " +
         std::to_string(report.Count(CheckStatus::kBad)) + " bad\n";
  return out;
}

}  // namespace hiltwin::app
