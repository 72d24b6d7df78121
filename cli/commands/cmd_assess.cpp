// `hiltwin assess`: credibility of a simulation against an experiment (thesis §2.4,
// appendix C), read from CSV files. It reports a score and a verdict; it exits 0 whenever the
// assessment completed, PASS or FAIL, so the exit code tells "ran" from "could not run".
// Flags -> AssessRunOptions (typed, read once) -> RunAssess (hiltwin/runs/assess_run.h).
#include <array>
#include <charconv>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "commands.h"
#include "hiltwin/assess/assessment.h"
#include "hiltwin/runs/assess_run.h"
#include "hiltwin/runs/output_files.h"
#include "hiltwin/tracing/csv.h"

namespace hiltwin::app {
namespace {

struct AssessCliOptions {
  std::string file;
  std::string sim;
  std::string exp;
  std::string input;
  std::string weights = "1,0,0";
  std::string segment;
  std::string band;
  std::optional<double> setpoint;
  std::optional<double> max_delay_s;
  double kp = 0.05;
  double eta_pass = 0.6;
  bool use_compensated = false;
  std::size_t welch_segment = 0;
  double coherence = 0.8;
  bool json = false;
  std::string plot;
};

// "[FILE:]COL". With a positional FILE, a prefix counts as a file only if it names one, so
// column names may contain ':'; without it, FILE:COL is required.
CurveSpec ParseSpec(const std::string& value, const std::string& positional, const char* flag) {
  const auto colon = value.rfind(':');
  if (colon != std::string::npos && colon > 0 && colon + 1 < value.size()) {
    const std::string prefix = value.substr(0, colon);
    std::error_code ec;
    if (positional.empty() || std::filesystem::is_regular_file(prefix, ec)) {
      return {prefix, value.substr(colon + 1)};
    }
  }
  if (positional.empty()) {
    ThrowUsage(std::string(flag) + " " + value +
                ": which file? Give FILE as the first argument (hiltwin assess FILE " + flag +
                " COL) or name it here (" + flag + " FILE.csv:COL)");
  }
  return {positional, value};
}

double ParseDouble(const std::string& text, const std::string& what) {
  double value = 0.0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (!text.empty() && text.front() == '+') ++first;
  const auto result = std::from_chars(first, last, value);
  if (result.ec != std::errc() || result.ptr != last || text.empty()) {
    ThrowUsage(what + ": '" + text + "' is not a number");
  }
  return value;
}

std::array<double, 3> ParseWeights(const std::string& text) {
  std::array<double, 3> weights{};
  std::size_t start = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t comma = text.find(',', start);
    if ((i < 2) == (comma == std::string::npos)) {
      ThrowUsage("--weights " + text + ": give three numbers t,p,f (time, performance, "
                  "frequency), e.g. 1,0,0 as the thesis chose");
    }
    const std::string part = text.substr(start, i < 2 ? comma - start : std::string::npos);
    weights[i] = ParseDouble(part, "--weights " + text);
    start = comma + 1;
  }
  return weights;
}

std::pair<double, double> ParseRange(const std::string& text, const std::string& flag,
                                     const char* example) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    ThrowUsage(flag + " " + text + ": give a range LO:HI, e.g. " + flag + " " + example);
  }
  return {ParseDouble(text.substr(0, colon), flag + " " + text),
          ParseDouble(text.substr(colon + 1), flag + " " + text)};
}

// The library names its choices as domain values; the command names them by flag, in advice
// (through AssessOptions::name_option) and in front of each OptionError.
std::string_view FlagOf(analysis::AssessOption option) {
  using analysis::AssessOption;
  switch (option) {
    case AssessOption::kSim: return "--sim";
    case AssessOption::kExp: return "--exp";
    case AssessOption::kInput: return "--input";
    case AssessOption::kKp: return "--kp";
    case AssessOption::kEtaPass: return "--eta-pass";
    case AssessOption::kWeights: return "--weights";
    case AssessOption::kSegment: return "--segment";
    case AssessOption::kMaxDelay: return "--max-delay";
    case AssessOption::kWelchSegment: return "--welch-segment";
    case AssessOption::kCoherence: return "--coherence";
    case AssessOption::kBand: return "--band";
  }
  return {};
}

// "--segment 5:2: ": the flag and its value, as typed wherever the command keeps the text.
std::string FlagPrefix(const AssessCliOptions& o, analysis::AssessOption option) {
  using analysis::AssessOption;
  using analysis::NumberText;
  std::string value;
  switch (option) {
    case AssessOption::kSim: value = o.sim.empty() ? "2" : o.sim; break;
    case AssessOption::kExp: value = o.exp.empty() ? "3" : o.exp; break;
    case AssessOption::kInput: value = o.input; break;
    case AssessOption::kKp: value = NumberText(o.kp); break;
    case AssessOption::kEtaPass: value = NumberText(o.eta_pass); break;
    case AssessOption::kWeights: value = o.weights; break;
    case AssessOption::kSegment: value = o.segment; break;
    case AssessOption::kMaxDelay: value = o.max_delay_s ? NumberText(*o.max_delay_s) : ""; break;
    case AssessOption::kWelchSegment:
      value = o.welch_segment > 0 ? std::to_string(o.welch_segment) : "";
      break;
    case AssessOption::kCoherence: value = NumberText(o.coherence); break;
    case AssessOption::kBand: value = o.band; break;
  }
  return std::string(FlagOf(option)) + (value.empty() ? "" : " " + value) + ": ";
}

// Every file assess reads and writes, for CheckFilesDistinct: a curve's file as the flag that
// named it (FILE when it is the positional one), and --plot.
std::vector<NamedFile> AssessFiles(const AssessCliOptions& o, const AssessRunOptions& run) {
  const auto curve_file = [&o](const char* flag, const CurveSpec& spec) {
    return NamedFile{spec.file == o.file ? "FILE" : flag, spec.file, false};
  };
  std::vector<NamedFile> files = {curve_file("--sim", run.sim), curve_file("--exp", run.exp),
                                  {"--plot", o.plot, true}};
  if (run.input) files.push_back(curve_file("--input", *run.input));
  return files;
}

// The flags' text, read once: the curves' specs, the weights and ranges as numbers, and the
// library's options, which name their choices by flag (FlagOf) and the flags' values as typed.
AssessRunOptions AssessRunOptionsOf(const AssessCliOptions& o) {
  if (o.file.empty() && (o.sim.empty() || o.exp.empty())) {
    ThrowUsage("nothing to compare: give FILE (columns 2 and 3 are the simulation and the "
                "experiment, as thesis appendix C), or --sim A.csv:COL --exp B.csv:COL");
  }
  AssessRunOptions run;
  run.sim = ParseSpec(o.sim.empty() ? "2" : o.sim, o.file, "--sim");
  run.exp = ParseSpec(o.exp.empty() ? "3" : o.exp, o.file, "--exp");
  if (!o.input.empty()) run.input = ParseSpec(o.input, o.file, "--input");

  analysis::AssessOptions& options = run.assess;
  options.params.kp = o.kp;
  options.params.eta_pass = o.eta_pass;
  options.weights = ParseWeights(o.weights);
  if (!o.segment.empty()) options.segment = ParseRange(o.segment, "--segment", "2:5");
  if (!o.band.empty()) options.band_hz = ParseRange(o.band, "--band", "0:20");
  options.setpoint = o.setpoint;
  options.max_delay_s = o.max_delay_s;
  options.total_uses_compensated = o.use_compensated;
  options.welch_segment = o.welch_segment;
  options.coherence_min = o.coherence;
  options.name_option = FlagOf;
  run.plot = o.plot;
  run.json = o.json;
  run.flag_prefix = [o](analysis::AssessOption option) { return FlagPrefix(o, option); };
  CheckFilesDistinct(AssessFiles(o, run));
  return run;
}

Command AddAssessCommand(CLI::App& parent) {
  auto o = std::make_shared<AssessCliOptions>();
  CLI::App* app = parent.add_subcommand(
      "assess",
      "Score the credibility of two time series (CSV): time, performance, frequency domains.");
  app->add_option("FILE", o->file, "CSV file holding both curves (omit with --sim/--exp FILE:COL)");
  app->add_option("--sim", o->sim, "simulation curve y_s: [FILE:]COL (default: column 2 of FILE)");
  app->add_option("--exp", o->exp, "experiment curve y_e: [FILE:]COL (default: column 3 of FILE)");
  app->add_option("--input", o->input,
                  "[FILE:]COL of the input both systems were given; enables the frequency domain");
  app->add_option("--kp", o->kp, "confidence interval Kp: acceptable error as a fraction")
      ->default_val(0.05);
  app->add_option("--eta-pass", o->eta_pass, "passing score eta_pass in (0,1)")->default_val(0.6);
  app->add_option("--weights", o->weights,
                  "weights t,p,f of the time, performance and frequency scores in the total "
                  "(thesis 3.9: 1,0,0)")
      ->default_val("1,0,0");
  app->add_option("--segment", o->segment,
                  "t0:t1 in seconds: the step response for the performance domain (default: "
                  "the whole compared range; t0 should be the step instant)");
  app->add_option("--setpoint", o->setpoint,
                  "setpoint for the steady-state error (default: the experiment's final value)");
  app->add_option("--max-delay", o->max_delay_s,
                  "delay search range +-S seconds (default: 10 % of the compared range)");
  app->add_flag("--use-compensated", o->use_compensated,
                "put the delay-compensated time score in the total (default: the raw one, as "
                "the thesis)");
  app->add_option("--welch-segment", o->welch_segment,
                  "Welch segment length in samples (default: largest power of two <= n/8, "
                  "16..65536)");
  app->add_option("--coherence", o->coherence,
                  "use only frequencies where both coherences exceed this")
      ->default_val(0.8);
  app->add_option("--band", o->band,
                  "LO:HI in Hz: frequency band scored in the frequency domain (default: all)");
  app->add_flag("--json", o->json,
                "print the report as JSON: time_domain {e_t, eps_t, k_e, eta}, delay_s, "
                "time_domain_compensated, performance_domain, frequency_domain, cross_checks "
                "{theil, iso18571} (null when not computed, reason under not_computed), total, "
                "pass, verdict");
  app->add_option("--plot", o->plot,
                  "write FILE.png: both curves and their difference over time (thesis fig. "
                  "5.3); needs gnuplot (Debian package gnuplot-nox)");
  app->footer(
      "Scores a simulation y_s against an experiment y_e with the credibility method of Dai\n"
      "et al. (2021) as the thesis applies it (section 2.4, appendix C):\n"
      "  e_t = RMS(y_e - y_s), eps_t = Kp*(max y_e - min y_e), K_e = eta_pass/sqrt(1-eta_pass^2),\n"
      "  eta = K_e*eps_t / sqrt((K_e*eps_t)^2 + e_t^2)   (eta = eta_pass when e_t = eps_t).\n"
      "Also: the delay between the curves (cross-correlation, sub-sample) and the score after\n"
      "removing it; step-response metrics (performance domain); Welch frequency responses when\n"
      "--input is given (frequency domain); Theil's U and ISO/TS 18571 as cross-checks.\n"
      "Input: CSV as 20-sim's 'Save Data To File' or hiltwin's logs write it: a header row,\n"
      "first column time in seconds. Columns by header name or 1-based index.\n"
      "  hiltwin assess run.csv                      columns 2 (sim) and 3 (exp), as appendix C\n"
      "  hiltwin assess run.csv --sim model --exp robot\n"
      "  hiltwin assess --sim sim.csv:2 --exp robot.csv:pos_right   (two time bases: the\n"
      "      simulation is interpolated onto the experiment's samples over their overlap)\n"
      "Formulas and sources: docs/credibility.md.\n\n"
      "Verdict: PASS when total >= eta_pass, else FAIL; printed, and in --json as \"pass\".\n"
      "Exit code: 0 whenever the assessment completed, PASS or FAIL (read the verdict from\n"
      "the output or --json); 2 for bad usage or input (the message names file:line:column or\n"
      "the flag); 5 when gnuplot fails to write the plot; 1 for an internal error.");
  return Command{app, [o] { return RunAssess(AssessRunOptionsOf(*o)); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(50, AddAssessCommand);

}  // namespace hiltwin::app
