#include "hiltwin/runs/doctor_format.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>

namespace hiltwin::app {
namespace {

using kernel_glue::CheckStatus;
using kernel_glue::ProbeCheck;
using kernel_glue::ProbeReport;

ProbeCheck Check(std::string id, std::string name, std::string value, CheckStatus status,
                 std::string advice = {}, bool not_tried = false) {
  return ProbeCheck{std::move(id), std::move(name),   std::move(value),
                    status,        std::move(advice), not_tried};
}

// A report shaped like a KVM guest's: every status, a long advice with a command that must
// not be split, and a privilege try skipped by --no-try.
ProbeReport GuestReport() {
  ProbeReport report;
  report.checks.push_back(Check(
      "preemption", "preemption model",
      "PREEMPT_DYNAMIC, mode none (kernel config default; debugfs not mounted)", CheckStatus::kBad,
      "a kernel without full preemption can delay a wake-up by milliseconds; for wake-up latency "
      "in tens of microseconds use a PREEMPT_RT kernel (Debian 12: `sudo apt install "
      "linux-image-rt-amd64`, then boot it)"));
  report.checks.push_back(Check("sched_fifo", "SCHED_FIFO (tried)", "unknown (not tried)",
                                CheckStatus::kWarn, {}, /*not_tried=*/true));
  report.checks.push_back(
      Check("governor", "CPU governor", "performance on 2 CPUs", CheckStatus::kOk));
  report.checks.push_back(
      Check("rt_throttling", "RT throttling", "sched_rt_runtime_us = 950000 of 1000000 (95 %)",
            CheckStatus::kWarn,
            "for measurement: `echo -1 | sudo tee /proc/sys/kernel/sched_rt_runtime_us` (risk: a "
            "runaway SCHED_FIFO loop then locks up its CPU; restore 950000 afterwards)"));
  return report;
}

TEST(DoctorAdvice, WordsTheCommandsFlagOnlyForASkippedTry) {
  const ProbeReport report = GuestReport();
  EXPECT_EQ(DoctorAdvice(report.checks[1]),
            "run 'hiltwin doctor' without --no-try to try it for real (it is undone at once)");
  EXPECT_EQ(DoctorAdvice(report.checks[0]), report.checks[0].advice);  // the probe's own
  EXPECT_EQ(DoctorAdvice(report.checks[2]), "");
}

TEST(DoctorJson, ListsEveryCheckWithItsAdviceAndASummary) {
  const nlohmann::json json = DoctorJson(GuestReport());
  ASSERT_EQ(json.at("checks").size(), 4u);
  const auto& fifo = json.at("checks")[1];
  EXPECT_EQ(fifo.at("id"), "sched_fifo");
  EXPECT_EQ(fifo.at("name"), "SCHED_FIFO (tried)");
  EXPECT_EQ(fifo.at("value"), "unknown (not tried)");
  EXPECT_EQ(fifo.at("status"), "warn");
  EXPECT_EQ(fifo.at("advice"),
            "run 'hiltwin doctor' without --no-try to try it for real (it is undone at once)");
  EXPECT_EQ(json.at("checks")[0].at("status"), "bad");
  EXPECT_EQ(json.at("checks")[2].at("status"), "ok");
  EXPECT_EQ(json.at("checks")[2].at("advice"), "");
  EXPECT_EQ(json.at("summary"), (nlohmann::json{{"ok", 1}, {"warn", 2}, {"bad", 1}}));
}

TEST(DoctorText, HasAlignedColumnsAndWrappedAdvice) {
  const ProbeReport report = GuestReport();
  const std::string text = DoctorText(report);
  std::istringstream lines(text);
  std::string header;
  std::getline(lines, header);
  // The longest name is "SCHED_FIFO (tried)" (18): names, 2 spaces, an 8-wide status column.
  EXPECT_EQ(header, "CHECK               STATUS  VALUE");
  const std::size_t value_column = 28;
  std::size_t check_lines = 0;
  std::size_t advice_lines = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.empty()) break;
    if (line[0] == ' ') {
      // Advice: "-> " under the value column, continued after the arrow, wrapped at 100
      // columns; only a line holding a single `command` may run over, so it stays copyable.
      ++advice_lines;
      const std::string content = line.substr(line.find_first_not_of("-> "));
      const bool single_command =
          content.front() == '`' && content.find('`', 1) + 2 >= content.size();
      EXPECT_TRUE(line.size() <= 100u || single_command) << line;
      const auto first = line.find_first_not_of(' ');
      EXPECT_EQ(first, line.compare(first, 3, "-> ") == 0 ? value_column : value_column + 3)
          << line;
      EXPECT_EQ(std::count(line.begin(), line.end(), '`') % 2, 0) << "split command: " << line;
      continue;
    }
    const ProbeCheck& check = report.checks.at(check_lines++);
    EXPECT_EQ(line.rfind(check.name, 0), 0u) << line;
    EXPECT_EQ(line.substr(value_column), check.value) << line;
  }
  EXPECT_EQ(check_lines, 4u);
  EXPECT_GE(advice_lines, 5u);  // two wrapped advices, one skipped try; none for the ok line
  EXPECT_NE(text.find("\npreemption model    BAD     PREEMPT_DYNAMIC"), std::string::npos) << text;
  EXPECT_NE(text.find("\nCPU governor        ok      performance on 2 CPUs\nRT throttling"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("-> run 'hiltwin doctor' without --no-try"), std::string::npos) << text;
  EXPECT_NE(text.find("`sudo apt install linux-image-rt-amd64`"), std::string::npos) << text;
  const std::string counts = "\n\n1 ok, 2 warn, 1 bad\n";
  ASSERT_GE(text.size(), counts.size());
  EXPECT_EQ(text.substr(text.size() - counts.size()), counts) << text;
}

}  // namespace
}  // namespace hiltwin::app
