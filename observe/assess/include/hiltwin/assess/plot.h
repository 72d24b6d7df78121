#pragma once
/// `hiltwin assess --plot FILE.png`: both curves and their difference over time, laid out as
/// thesis fig. 5.3, rendered by gnuplot in a child process.

#include <string>

#include "hiltwin/assess/assessment.h"
#include "hiltwin/report_kit/gnuplot.h"  // PlotError

namespace hiltwin::analysis {

/// Writes `png_path`: top panel y_s and y_e, bottom panel y_s − y_e raw and delay-compensated.
/// Long records are thinned to at most `max_points` rows, keeping each bucket's extreme
/// differences. Throws InputError when gnuplot is not installed (naming the Debian package
/// gnuplot-nox), PlotError when it fails.
void WritePlot(const Assessment& assessment, const std::string& png_path,
               std::size_t max_points = 20000);

}  // namespace hiltwin::analysis
