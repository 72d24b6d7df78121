#include "hiltwin/runs/assess_run.h"

#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <system_error>

#include "hiltwin/assess/plot.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/tracing/csv.h"

namespace hiltwin::app {
namespace {

void CheckPlotDirectory(const std::string& plot) {
  if (plot.empty()) return;
  const std::filesystem::path parent = std::filesystem::path(plot).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
    ThrowUsage("--plot " + plot + ": directory " + parent.string() +
               " does not exist; create it or choose another path");
  }
}

void AssessAndReport(const AssessRunOptions& o) {
  std::map<std::string, analysis::CsvTable> tables;  // each file read once
  auto curve = [&](const CurveSpec& spec, const char* flag) {
    auto it = tables.find(spec.file);
    if (it == tables.end()) it = tables.emplace(spec.file, analysis::ReadCsv(spec.file)).first;
    return analysis::ExtractCurve(it->second,
                                  analysis::ResolveColumn(it->second, spec.column, flag));
  };
  const analysis::Curve sim = curve(o.sim, "--sim");
  const analysis::Curve exp = curve(o.exp, "--exp");
  std::optional<analysis::Curve> input;
  if (o.input) input = curve(*o.input, "--input");
  const analysis::Assessment result =
      analysis::Assess(sim, exp, input ? &*input : nullptr, o.assess);
  if (!o.plot.empty()) {
    try {
      analysis::WritePlot(result, o.plot);
    } catch (const analysis::InputError& e) {  // gnuplot is not installed
      ThrowUsage(std::string("--plot: ") + e.what() + ", or leave out --plot");
    } catch (const analysis::PlotError& e) {
      throw CommandError(ExitCode::kIo, std::string("--plot: ") + e.what());
    }
  }
  if (o.json) {
    std::printf("%s\n", analysis::ToJson(result).dump(2).c_str());
  } else {
    std::printf("%s", analysis::FormatText(result).c_str());
    if (!o.plot.empty()) std::printf("Plot written to %s\n", o.plot.c_str());
  }
}

}  // namespace

int RunAssess(const AssessRunOptions& o) {
  CheckPlotDirectory(o.plot);
  try {
    AssessAndReport(o);
  } catch (const analysis::OptionError& e) {
    ThrowUsage((o.flag_prefix ? o.flag_prefix(e.option()) : std::string()) + e.what());
  } catch (const analysis::InputError& e) {
    ThrowUsage(e.what());
  } catch (const analysis::PlotError& e) {
    throw CommandError(ExitCode::kIo, e.what());
  }
  return static_cast<int>(ExitCode::kPass);
}

}  // namespace hiltwin::app
