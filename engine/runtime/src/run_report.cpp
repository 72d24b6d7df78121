#include "hiltwin/runtime/run_report.h"

#include <csignal>
#include <cstdarg>
#include <cstdio>

#include "hiltwin/kernel_glue/stop_signal.h"

namespace hiltwin::runtime {
namespace {

using Json = nlohmann::ordered_json;
using lifecycle::StopReason;

Json Timing(const scheduler::TimingSummary& s) {
  return {{"min", s.min_ns},   {"mean", s.mean_ns}, {"p50", s.p50_ns}, {"p99", s.p99_ns},
          {"p999", s.p999_ns}, {"max", s.max_ns},   {"count", s.count}};
}

template <typename T>
Json OrNull(const std::optional<T>& value) {
  return value ? Json(*value) : Json(nullptr);
}

Json Constraint(const qos::RuleStatus& status) {
  Json parameters;
  switch (status.spec.kind) {
    case qos::RuleKind::kMkFirm:
      parameters = {{"m", status.spec.m}, {"k", status.spec.k}};
      break;
    case qos::RuleKind::kMissesInWindow:
      parameters = {{"n", status.spec.n}, {"k", status.spec.k}};
      break;
    case qos::RuleKind::kConsecutiveMisses:
      parameters = {{"n", status.spec.n}};
      break;
    case qos::RuleKind::kMissRatio:
      parameters = {{"max_miss_pct", status.spec.max_miss_pct}};
      break;
  }
  Json c = {{"kind", qos::ToString(status.spec.kind)},
            {"description", qos::Describe(status.spec)},
            {"parameters", parameters},
            {"violated", status.violated},
            {"violations", status.violations},
            {"first_violation_cycle", OrNull(status.first_violation_cycle)}};
  if (status.spec.kind == qos::RuleKind::kMkFirm) c["min_met_in_window"] = status.min_met_in_window;
  if (status.spec.kind == qos::RuleKind::kMkFirm ||
      status.spec.kind == qos::RuleKind::kMissesInWindow) {
    c["max_misses_in_window"] = status.max_misses_in_window;
  }
  return c;
}

Json QosPart(const RunReport& r) {
  const MissLedger& m = r.misses;
  return {{"policy", qos::ToString(r.qos_policy)},
          {"grace_cycles", m.grace_cycles},
          {"grace_misses", m.grace_misses},
          {"cycles_judged", m.cycles_judged},
          {"misses_judged", m.misses_judged},
          {"miss_pct_judged", m.miss_pct_judged},
          {"max_consecutive_misses_judged", m.max_consecutive_misses_judged},
          {"abort_cycle", OrNull(m.abort_cycle)}};
}

// The keys the contract names (docs/architecture.md, "Run report"), in its order.
Json ContractPart(const RunReport& r) {
  Json constraints = Json::array();
  for (const qos::RuleStatus& status : r.constraints) constraints.push_back(Constraint(status));
  const Conclusion conclusion = ConclusionOf(r);
  return {{"verdict", VerdictWord(conclusion)},
          {"complete", conclusion.complete},
          {"verdict_text", conclusion.text},
          {"stop_reason", lifecycle::ToString(r.stop_reason)},
          {"rate_hz", r.rate_hz},
          {"period_ns", r.period_ns},
          {"cycles_planned", r.cycles_planned},
          {"cycles_run", r.cycles_run},
          {"deadline_misses", r.misses.deadline_misses},
          {"miss_pct", r.misses.miss_pct},
          {"max_consecutive_misses", r.misses.max_consecutive_misses},
          {"constraints", constraints},
          {"latency_ns", Timing(r.latency)},
          {"compute_ns", Timing(r.compute)},
          {"response_ns", Timing(r.response)},
          {"log_rows_written", r.log ? r.log->rows_written : 0},
          {"log_rows_dropped", r.log ? r.log->rows_dropped : 0}};
}

}  // namespace

const char* ToString(ClockKind clock) noexcept {
  return clock == ClockKind::kVirtual ? "virtual" : "realtime";
}

Json ToJson(const RunReport& r) {
  Json json = ContractPart(r);
  // Beyond the contract: what a reader needs to judge or reproduce the run.
  json["io_ns"] = Timing(r.io_time);
  json["period_jitter_ns"] = Timing(r.period_jitter);
  json["miss_counts_include_grace"] = true;  // deadline_misses, miss_pct, max_consecutive_misses
  json["releases_recorded"] = r.misses.releases;
  json["releases"] = r.releases;
  json["releases_skipped"] = r.releases_skipped;
  json["cycles_paused"] = r.cycles_paused;
  json["deadline_ns"] = r.deadline_ns;
  json["overrun_policy"] = std::string(scheduler::ToString(r.overrun_policy));
  json["qos"] = QosPart(r);
  json["task"] = r.task_name;
  json["clock"] = ToString(r.clock);
  json["io"] = r.io;
  json["io_errors"] = r.link.io_errors;
  json["pulse_limit_cycles"] = r.link.pulse_limit_cycles;
  json["peer"] = r.link.peer_name;
  json["peer_absent_cycles"] = r.link.peer_absent_cycles;
  json["peer_stopped"] = r.link.peer_stopped.empty() ? Json(nullptr) : Json(r.link.peer_stopped);
  for (const auto& [key, value] : r.details) json[key] = value;
  json["log_path"] = r.log ? Json(r.log->path) : Json(nullptr);
  // Every row the log should hold is one of written, dropped (log_rows_dropped, a contract
  // key) or lost to a write error (disk full, file-size limit): the three add up.
  json["log_rows_lost"] = r.log ? r.log->rows_lost : 0;
  if (r.log && !r.log->error.empty()) json["log_error"] = r.log->error;
  json["timing_log_path"] = r.timing_log ? Json(r.timing_log->path) : Json(nullptr);
  if (r.timing_log) {
    json["timing_log_rows_written"] = r.timing_log->rows_written;
    json["timing_log_rows_dropped"] = r.timing_log->rows_dropped;
    json["timing_log_rows_lost"] = r.timing_log->rows_lost;
    if (!r.timing_log->error.empty()) json["timing_log_error"] = r.timing_log->error;
  }
  json["final_state"] = lifecycle::ToString(r.final_state);
  json["stop_signal"] =
      r.stop_signal > 0 ? Json(kernel_glue::StopSignalName(r.stop_signal)) : Json(nullptr);
  json["outputs_safe"] = r.outputs_safe;
  if (r.fault) {
    json["fault"] = {{"kind", lifecycle::ToString(r.fault->kind)},
                     {"cycle", r.fault->cycle},
                     {"reason", r.fault->reason}};
  }
  json["wall_time_s"] = r.wall_time_s;
  json["rt_setup"] = r.rt_setup ? Json(kernel_glue::ToJson(*r.rt_setup)) : Json(nullptr);
  json["warnings"] = r.warnings;
  return json;
}

namespace {

// printf into a std::string; every line of the summary is short.
[[gnu::format(printf, 2, 3)]] void Append(std::string& out, const char* format, ...) {
  char line[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  out += line;
}

using ull = unsigned long long;

void AppendMisses(std::string& out, const RunReport& r) {
  const MissLedger& m = r.misses;
  Append(out,
         "misses     %llu of %llu releases (%.3f %%), longest run %llu, skipped releases %llu\n",
         static_cast<ull>(m.deadline_misses), static_cast<ull>(m.releases), m.miss_pct,
         static_cast<ull>(m.max_consecutive_misses), static_cast<ull>(r.releases_skipped));
  if (m.grace_cycles > 0) {
    Append(out,
           "judged     %llu misses of %llu releases (%.3f %%) after the grace period; the first "
           "%llu releases (%llu misses) are not judged\n",
           static_cast<ull>(m.misses_judged), static_cast<ull>(m.cycles_judged), m.miss_pct_judged,
           static_cast<ull>(m.grace_cycles), static_cast<ull>(m.grace_misses));
  }
}

void AppendTiming(std::string& out, const char* label, const scheduler::TimingSummary& t) {
  auto us = [](std::int64_t ns) { return static_cast<double>(ns) / 1000.0; };
  Append(out, "%-10s min %8.1f  p50 %8.1f  p99 %8.1f  p99.9 %8.1f  max %9.1f us\n", label,
         us(t.min_ns), us(t.p50_ns), us(t.p99_ns), us(t.p999_ns), us(t.max_ns));
}

void AppendRules(std::string& out, const RunReport& r) {
  for (const qos::RuleStatus& c : r.constraints) {
    const std::string first =
        c.first_violation_cycle ? std::to_string(*c.first_violation_cycle) : std::string("-");
    Append(out, "rule       %-40s %s (violating windows %llu, first at cycle %s)\n",
           qos::Describe(c.spec).c_str(), c.violated ? "VIOLATED" : "ok",
           static_cast<ull>(c.violations), first.c_str());
  }
}

// "run.csv: 4900 rows written, 0 dropped, 75062 lost (No space left on device)"; the lost
// part only when the file refused rows.
void AppendLog(std::string& out, const char* label, const LogFigures& log) {
  Append(out, "%s %s: %llu rows written, %llu dropped", label, log.path.c_str(),
         static_cast<ull>(log.rows_written), static_cast<ull>(log.rows_dropped));
  if (log.rows_lost > 0 || !log.lost_reason.empty()) {
    Append(out, ", %llu lost (%s)", static_cast<ull>(log.rows_lost),
           log.lost_reason.empty() ? "write error" : log.lost_reason.c_str());
  }
  out += "\n";
}

// Why a log is incomplete and what is in it: "the log run.csv is incomplete: write 'run.csv':
// No space left on device; it ends with its last whole row: 4900 rows written, 75062 lost".
std::string IncompleteLogLine(const char* what, const LogFigures& log) {
  std::string line = std::string(what) + " " + log.path + " is incomplete: " + log.error;
  if (log.rows_lost > 0) {
    line += "; it ends with its last whole row: " + std::to_string(log.rows_written) +
            " rows written, " + std::to_string(log.rows_lost) + " lost";
  }
  return line;
}

// "I/O fault at cycle 2000".
std::string FaultAt(const RunFault& fault) {
  return std::string(fault.kind == StopReason::kIoFault ? "I/O" : "model") + " fault at cycle " +
         std::to_string(fault.cycle);
}

// Why no cycle was judged, from the stop reason.
std::string WhyNoVerdict(const RunReport& r) {
  std::string why = "NONE (no cycle was judged";
  if (r.fault) return why + "; the run did NOT finish: " + FaultAt(*r.fault) + ")";
  switch (r.stop_reason) {
    case StopReason::kStopRequested:
      return why + ": stopped by " +
             (r.stop_signal > 0 ? kernel_glue::StopSignalName(r.stop_signal) : "a stop command") +
             " before the first judged cycle)";
    case StopReason::kPeerStopped:
      return why + ": the " + r.link.peer_name + " stopped before the first judged cycle)";
    default:
      return why + "; stop: " + lifecycle::ToString(r.stop_reason) + ")";
  }
}

std::string VerdictText(const RunReport& r) {
  std::string line = qos::ToString(r.verdict);
  if (r.verdict == qos::Verdict::kFlagged)
    line += " (deadline constraints violated: results unreliable)";
  if (r.verdict == qos::Verdict::kAborted) {
    line += r.outputs_safe
                ? " (stopped at the first violation; outputs put in their safe state)"
                : " (stopped at the first violation; the safe outputs could NOT be written)";
  }
  // The verdict judges timing only. A run that a fault ended did not do what was asked: say so
  // on the verdict's own line, so a PASS is never read as "the run is good".
  if (r.fault) {
    line += std::string(" for the timing of the ") + std::to_string(r.cycles_run) +
            " cycles run; the run did NOT finish: " + FaultAt(*r.fault);
  }
  return line;
}

}  // namespace

std::string FormatSummary(const RunReport& r) {
  std::string out;
  Append(out, "cycles     %llu of %llu at %.0f Hz (%s clock), stop: %s%s%s\n",
         static_cast<ull>(r.cycles_run), static_cast<ull>(r.cycles_planned), r.rate_hz,
         ToString(r.clock), lifecycle::ToString(r.stop_reason), r.stop_signal > 0 ? " by " : "",
         r.stop_signal > 0 ? kernel_glue::StopSignalName(r.stop_signal) : "");
  if (r.cycles_paused > 0)
    Append(out, "paused     %llu cycles\n", static_cast<ull>(r.cycles_paused));
  AppendMisses(out, r);
  AppendTiming(out, "latency", r.latency);
  AppendTiming(out, "compute", r.compute);
  AppendTiming(out, "io", r.io_time);
  AppendTiming(out, "response", r.response);
  AppendRules(out, r);
  const LinkFigures& l = r.link;
  if (l.io_errors + l.pulse_limit_cycles + l.peer_absent_cycles > 0) {
    Append(out,
           "link       %llu frames corrupted or missed (inputs held), %llu cycles with an encoder "
           "change over the pulse limit, no %s in %llu cycles\n",
           static_cast<ull>(l.io_errors), static_cast<ull>(l.pulse_limit_cycles),
           l.peer_name.c_str(), static_cast<ull>(l.peer_absent_cycles));
  }
  if (r.log) AppendLog(out, "log       ", *r.log);
  if (r.timing_log) AppendLog(out, "timing log", *r.timing_log);
  if (!l.peer_stopped.empty()) Append(out, "peer       %s\n", l.peer_stopped.c_str());
  if (r.fault) {
    Append(out, "fault      %s at cycle %llu: %s\n", lifecycle::ToString(r.fault->kind),
           static_cast<ull>(r.fault->cycle), r.fault->reason.c_str());
  }
  if (!r.outputs_safe) out += "outputs    the safe outputs could NOT be written: check the link\n";
  for (const std::string& warning : r.warnings) Append(out, "warning    %s\n", warning.c_str());
  return out + "verdict    " + ConclusionOf(r).text + "\n";
}

Conclusion ConclusionOf(const RunReport& r) {
  Conclusion c;
  // A verdict over no judged cycle would be a PASS about nothing.
  if (r.misses.cycles_judged == 0) {
    c.text = WhyNoVerdict(r);
    return c;
  }
  c.verdict = r.verdict;
  c.complete = !r.fault;
  c.text = VerdictText(r);
  return c;
}

const char* VerdictWord(const Conclusion& c) noexcept {
  return c.verdict ? qos::ToString(*c.verdict) : "NONE";
}

std::vector<std::string> Problems(const RunReport& r) {
  std::vector<std::string> lines;
  if (r.fault) lines.push_back(FaultAt(*r.fault) + ": " + r.fault->reason);
  if (r.link.io_errors > 0) {
    lines.push_back("warning: " + std::to_string(r.link.io_errors) +
                    " frames on the link were corrupted or missed; the inputs were held over "
                    "those cycles, so the results there rest on stale inputs");
  }
  if (r.link.peer_absent_cycles > 0) {
    lines.push_back("warning: no " + r.link.peer_name + " was attached to " + r.io + " in " +
                    std::to_string(r.link.peer_absent_cycles) + " of " +
                    std::to_string(r.cycles_run) +
                    " cycles; the inputs were idle then. Start the " + r.link.peer_name +
                    " process on the same wire before or during the run.");
  }
  if (r.log && !r.log->error.empty()) lines.push_back(IncompleteLogLine("the log", *r.log));
  if (r.timing_log && !r.timing_log->error.empty()) {
    lines.push_back(IncompleteLogLine("the timing log", *r.timing_log));
  } else if (r.timing_log && r.timing_log->rows_dropped > 0) {
    lines.push_back("warning: the timing log " + r.timing_log->path + " lost " +
                    std::to_string(r.timing_log->rows_dropped) +
                    " rows (its writer fell behind); an analysis of it misses those cycles");
  }
  return lines;
}

ExitCode ExitCodeFor(const RunReport& r) noexcept {
  const bool io_fault =
      r.stop_reason == StopReason::kIoFault || r.fault_while_stopping == StopReason::kIoFault;
  if (io_fault) return ExitCode::kIo;
  if (r.stop_reason == StopReason::kModelFault ||
      r.fault_while_stopping == StopReason::kModelFault) {
    return ExitCode::kInternal;
  }
  if (r.log && !r.log->error.empty()) return ExitCode::kIo;
  if (r.timing_log && !r.timing_log->error.empty()) return ExitCode::kIo;
  if (r.misses.cycles_judged == 0) {
    // No verdict. Stopped on request: the code the shell would show had the signal ended the
    // process (a stop command stands for SIGTERM, as docs/telemetry.md says). Otherwise the peer
    // went before the first judged cycle: the link's failure, as a peer that never came.
    if (r.stop_reason != StopReason::kStopRequested) return ExitCode::kIo;
    return StoppedBy(r.stop_signal > 0 ? r.stop_signal : SIGTERM);
  }
  switch (r.verdict) {
    case qos::Verdict::kPass:
      return ExitCode::kPass;
    case qos::Verdict::kFlagged:
      return ExitCode::kFlagged;
    case qos::Verdict::kAborted:
      return ExitCode::kAborted;
  }
  return ExitCode::kInternal;
}

}  // namespace hiltwin::runtime
