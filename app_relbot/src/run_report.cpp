#include "hiltwin/app_relbot/run_report.h"

#include <cstdio>

namespace hiltwin::app {
namespace {

nlohmann::ordered_json Timing(const scheduler::TimingStats& stats) {
  const scheduler::TimingSummary s = stats.Summary();
  return {{"min", s.min_ns}, {"mean", s.mean_ns}, {"p50", s.p50_ns}, {"p99", s.p99_ns},
          {"p999", s.p999_ns}, {"max", s.max_ns}, {"count", s.count}};
}

nlohmann::ordered_json Constraint(const qos::RuleStatus& status) {
  nlohmann::ordered_json parameters;
  switch (status.spec.kind) {
    case qos::RuleKind::kMkFirm: parameters = {{"m", status.spec.m}, {"k", status.spec.k}}; break;
    case qos::RuleKind::kMissesInWindow: parameters = {{"n", status.spec.n}, {"k", status.spec.k}}; break;
    case qos::RuleKind::kConsecutiveMisses: parameters = {{"n", status.spec.n}}; break;
    case qos::RuleKind::kMissRatio: parameters = {{"max_miss_pct", status.spec.max_miss_pct}}; break;
  }
  nlohmann::ordered_json c = {{"kind", qos::ToString(status.spec.kind)},
                      {"description", qos::Describe(status.spec)},
                      {"parameters", parameters},
                      {"violated", status.violated},
                      {"violations", status.violations},
                      {"first_violation_cycle", nullptr}};
  if (status.first_violation_cycle) c["first_violation_cycle"] = *status.first_violation_cycle;
  if (status.spec.kind == qos::RuleKind::kMkFirm) c["min_met_in_window"] = status.min_met_in_window;
  if (status.spec.kind == qos::RuleKind::kMkFirm || status.spec.kind == qos::RuleKind::kMissesInWindow) {
    c["max_misses_in_window"] = status.max_misses_in_window;
  }
  return c;
}

}  // namespace

nlohmann::ordered_json BuildRunReport(const RunFacts& facts, const scheduler::Executive& executive,
                              const qos::QosMonitor& monitor, const kernel_glue::RtSetupRecord& rt) {
  const scheduler::ExecutiveStats& stats = executive.stats();
  const double miss_pct =
      stats.releases == 0 ? 0.0
                          : 100.0 * static_cast<double>(stats.deadline_misses) /
                                static_cast<double>(stats.releases);
  nlohmann::ordered_json constraints = nlohmann::ordered_json::array();
  for (const qos::RuleStatus& status : monitor.rules()) constraints.push_back(Constraint(status));

  nlohmann::ordered_json report = {
      {"verdict", qos::ToString(monitor.verdict())},
      {"stop_reason", facts.stop_reason},
      {"rate_hz", facts.rate_hz},
      {"period_ns", executive.config().period_ns},
      {"cycles_planned", facts.cycles_planned},
      {"cycles_run", stats.cycles_run},
      {"deadline_misses", stats.deadline_misses},
      {"miss_pct", miss_pct},
      {"max_consecutive_misses", stats.max_consecutive_misses},
      {"constraints", constraints},
      {"latency_ns", Timing(stats.wake_latency)},
      {"compute_ns", Timing(stats.compute)},
      {"response_ns", Timing(stats.response)},
      {"log_rows_written", facts.log_rows_written},
      {"log_rows_dropped", facts.log_rows_dropped},
      // Beyond the contract: what a reader needs to judge or reproduce the run.
      {"period_jitter_ns", Timing(stats.period_jitter)},
      {"releases", stats.releases},
      {"releases_skipped", stats.releases_skipped},
      {"deadline_ns", executive.deadline_ns()},
      {"overrun_policy", std::string(scheduler::ToString(executive.config().overrun_policy))},
      {"qos",
       {{"policy", qos::ToString(monitor.config().policy)},
        {"grace_cycles", monitor.config().grace_cycles},
        {"cycles_judged", monitor.cycles_recorded()},
        {"misses_judged", monitor.misses()},
        {"miss_pct_judged", monitor.miss_pct()},
        {"abort_cycle", monitor.abort_cycle() ? nlohmann::ordered_json(*monitor.abort_cycle()) : nlohmann::ordered_json(nullptr)}}},
      {"clock", facts.clock},
      {"io", facts.io},
      {"io_errors", facts.io_errors},
      {"encoder_counts_over_limit", facts.counts_over_limit},
      {"controller_absent_cycles", facts.controller_absent_cycles},
      {"input", facts.input},
      {"integrator", facts.integrator},
      {"log_path", facts.log_path.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(facts.log_path)},
      {"wall_time_s", facts.wall_time_s},
      {"rt_setup", kernel_glue::ToJson(rt)},
  };
  return report;
}

std::string FormatRunSummary(const nlohmann::ordered_json& r) {
  auto us = [](const nlohmann::ordered_json& t, const char* key) {
    return t.at(key).get<double>() / 1000.0;
  };
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "cycles     %llu of %llu at %.0f Hz (%s clock), stop: %s\n",
                r.at("cycles_run").get<unsigned long long>(),
                r.at("cycles_planned").get<unsigned long long>(), r.at("rate_hz").get<double>(),
                r.at("clock").get<std::string>().c_str(), r.at("stop_reason").get<std::string>().c_str());
  out += line;
  std::snprintf(line, sizeof line, "misses     %llu (%.3f %%), longest run %llu, skipped releases %llu\n",
                r.at("deadline_misses").get<unsigned long long>(), r.at("miss_pct").get<double>(),
                r.at("max_consecutive_misses").get<unsigned long long>(),
                r.at("releases_skipped").get<unsigned long long>());
  out += line;
  for (const char* key : {"latency_ns", "compute_ns", "response_ns"}) {
    const auto& t = r.at(key);
    std::snprintf(line, sizeof line, "%-10.*s min %8.1f  p50 %8.1f  p99 %8.1f  p99.9 %8.1f  max %9.1f us\n",
                  static_cast<int>(std::string_view(key).find('_')), key, us(t, "min"), us(t, "p50"),
                  us(t, "p99"), us(t, "p999"), us(t, "max"));
    out += line;
  }
  for (const auto& c : r.at("constraints")) {
    std::string first = c.at("first_violation_cycle").is_null()
                            ? std::string("-")
                            : std::to_string(c.at("first_violation_cycle").get<unsigned long long>());
    std::snprintf(line, sizeof line, "rule       %-40s %s (violating windows %llu, first at cycle %s)\n",
                  c.at("description").get<std::string>().c_str(),
                  c.at("violated").get<bool>() ? "VIOLATED" : "ok",
                  c.at("violations").get<unsigned long long>(), first.c_str());
    out += line;
  }
  const auto io_errors = r.at("io_errors").get<unsigned long long>();
  const auto over_limit = r.at("encoder_counts_over_limit").get<unsigned long long>();
  const auto absent = r.at("controller_absent_cycles").get<unsigned long long>();
  if (io_errors + over_limit + absent > 0) {
    std::snprintf(line, sizeof line,
                  "io         %llu frames corrupted or missed (inputs held), %llu encoder changes "
                  "over the pulse limit, no controller in %llu cycles\n",
                  io_errors, over_limit, absent);
    out += line;
  }
  if (!r.at("log_path").is_null()) {
    std::snprintf(line, sizeof line, "log        %s: %llu rows written, %llu dropped\n",
                  r.at("log_path").get<std::string>().c_str(),
                  r.at("log_rows_written").get<unsigned long long>(),
                  r.at("log_rows_dropped").get<unsigned long long>());
    out += line;
  }
  out += "verdict    " + r.at("verdict").get<std::string>();
  const std::string verdict = r.at("verdict").get<std::string>();
  if (verdict == "FLAGGED") out += " (deadline constraints violated: results unreliable)";
  if (verdict == "ABORTED") out += " (stopped at the first violation; outputs put in their safe state)";
  out += "\n";
  return out;
}

}  // namespace hiltwin::app
