#pragma once
/// `hiltwin assess`'s run: read the curves from their CSV files, assess them (assess's
/// assessment.h), write the plot and print the report. The command (cli/commands/cmd_assess.cpp)
/// parses its flags, once, into AssessRunOptions.

#include <functional>
#include <optional>
#include <string>

#include "hiltwin/assess/assessment.h"

namespace hiltwin::app {

/// One curve: a CSV file and a column of it, by header name or 1-based index.
struct CurveSpec {
  std::string file;
  std::string column;
};

struct AssessRunOptions {
  CurveSpec sim;                   ///< the simulation y_s
  CurveSpec exp;                   ///< the experiment y_e
  std::optional<CurveSpec> input;  ///< the input both were given; enables the frequency domain
  analysis::AssessOptions assess;  ///< every choice of the assessment, typed
  std::string plot;                ///< PNG to write; empty: no plot
  bool json = false;               ///< print the report as JSON instead of the text table
  /// The flag and its value as the user typed them, put in front of an OptionError's message
  /// ("--segment 5:2: "); empty: the message alone.
  std::function<std::string(analysis::AssessOption)> flag_prefix;
};

/// Assesses and prints the report; returns 0 whenever the assessment completed, PASS or FAIL.
/// Throws CommandError: exit 2 for bad usage or input (naming file:line:column or the flag),
/// 5 when gnuplot fails to write the plot.
int RunAssess(const AssessRunOptions& o);

}  // namespace hiltwin::app
