#include "hiltwin/assess/assessment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <stdexcept>
#include <tuple>

#include "hiltwin/assess/series.h"
#include "hiltwin/report_kit/string_format.h"

namespace hiltwin::analysis {
namespace {

using detail::Format;

std::string Num(double v) { return Format("%.6g", v); }

// "5 s to 2 s": a range as the user gave it, in its unit.
std::string FromTo(const std::pair<double, double>& range, const char* unit) {
  return Num(range.first) + " " + unit + " to " + Num(range.second) + " " + unit;
}

void CheckOptions(const AssessOptions& o) {
  const auto& p = o.params;
  if (!(std::isfinite(p.kp) && p.kp > 0.0 && p.kp < 1.0)) {
    throw OptionError(AssessOption::kKp, "confidence interval Kp " + Num(p.kp) +
                                             ": must lie strictly between 0 and 1 (thesis: 0.05)");
  }
  if (!(p.eta_pass > 0.0 && p.eta_pass < 1.0)) {
    throw OptionError(AssessOption::kEtaPass,
                      "passing score eta_pass " + Num(p.eta_pass) +
                          ": must lie strictly between 0 and 1 (thesis: 0.6)");
  }
  const std::string weights =
      "weights " + Num(o.weights[0]) + "," + Num(o.weights[1]) + "," + Num(o.weights[2]) + ": ";
  double sum = 0.0;
  for (const double w : o.weights) {
    if (!(std::isfinite(w) && w >= 0.0)) {
      throw OptionError(AssessOption::kWeights,
                        weights + "every weight must be a number >= 0 (thesis: 1,0,0)");
    }
    sum += w;
  }
  if (!(sum > 0.0)) {
    throw OptionError(AssessOption::kWeights,
                      weights + "at least one weight must be > 0 (thesis: 1,0,0)");
  }
  if (o.segment && !(o.segment->second > o.segment->first)) {
    throw OptionError(AssessOption::kSegment,
                      "segment " + FromTo(*o.segment, "s") +
                          ": the end must come after the start (times in seconds, start first)");
  }
  if (o.max_delay_s && !(*o.max_delay_s >= 0.0)) {
    throw OptionError(AssessOption::kMaxDelay, "delay search range " + Num(*o.max_delay_s) +
                                                   " s: must be a time in seconds >= 0");
  }
  if (o.band_hz && !(o.band_hz->first >= 0.0 && o.band_hz->second > o.band_hz->first)) {
    throw OptionError(AssessOption::kBand, "frequency band " + FromTo(*o.band_hz, "Hz") +
                                               ": need 0 <= low < high, e.g. 0 Hz to 20 Hz");
  }
  if (!(o.coherence_min >= 0.0 && o.coherence_min < 1.0)) {
    throw OptionError(AssessOption::kCoherence, "coherence threshold " + Num(o.coherence_min) +
                                                    ": must lie in [0, 1) (default 0.8)");
  }
}

// Indices [first, last) of the samples of `t` inside [lo, hi] (with a rounding allowance).
std::pair<std::size_t, std::size_t> Inside(const std::vector<double>& t, double lo, double hi) {
  const double slack = 1e-9 * std::max({std::abs(lo), std::abs(hi), 1.0});
  const auto first = std::lower_bound(t.begin(), t.end(), lo - slack) - t.begin();
  const auto last = std::upper_bound(t.begin(), t.end(), hi + slack) - t.begin();
  return {static_cast<std::size_t>(first), static_cast<std::size_t>(std::max(first, last))};
}

std::string Range(const Curve& c) {
  return "[" + Num(c.t_s.front()) + ", " + Num(c.t_s.back()) + "] s";
}

// "FILE:FIRSTLINE-LASTLINE:COLUMN" of samples [first, last] of `c` (column 0-based; 0 = time).
std::string Lines(const Curve& c, std::size_t first, std::size_t last, std::size_t column) {
  if (last >= c.lines.size() || first > last) return c.path;  // curve not read from a file
  return c.path + ":" + std::to_string(c.lines[first]) + "-" + std::to_string(c.lines[last]) +
         ":" + std::to_string(column + 1);
}

nlohmann::json Opt(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

nlohmann::json TimeJson(const TimeDomainScore& s) {
  return {{"e_t", s.e_t}, {"eps_t", s.eps_t}, {"k_e", s.k_e}, {"eta", s.eta}, {"samples", s.samples}};
}

nlohmann::json DomainJson(const DomainScore& s) {
  return {{"e", s.e}, {"eps", s.eps}, {"k_e", s.k_e}, {"eta", s.eta}};
}

std::string OptText(const std::optional<double>& v) { return v ? Format("%.6g", *v) : "-"; }

}  // namespace

Curve ExtractCurve(const CsvTable& table, std::size_t column) {
  if (column == 0 || column >= table.columns.size()) {
    throw std::invalid_argument("ExtractCurve: column out of range or time");
  }
  Curve c;
  c.path = table.path;
  c.column = column;
  c.label = table.path + " " + table.ColumnLabel(column);
  c.t_s = table.columns[0];
  c.y = table.columns[column];
  c.lines = table.lines;
  return c;
}

namespace {

// Samples [first, last) of the experiment inside the time range both curves cover.
struct Overlap {
  std::size_t first = 0;
  std::size_t last = 0;
};

// The overlap on the experiment's time base (the thesis compares at the logged samples); fills
// the aligned series of `a`.
Overlap AlignOnOverlap(const Curve& sim, const Curve& exp, Assessment& a) {
  const double lo = std::max(sim.t_s.front(), exp.t_s.front());
  const double hi = std::min(sim.t_s.back(), exp.t_s.back());
  const auto [first, last] = Inside(exp.t_s, lo, hi);
  if (!(lo < hi) || last - first < 2) {
    throw InputError("no overlap in time: the simulation " + sim.label + " has its time at " +
                     Lines(sim, 0, sim.t_s.size() - 1, 0) + ", covering " + Range(sim) +
                     "; the experiment " + exp.label + " has its time at " +
                     Lines(exp, 0, exp.t_s.size() - 1, 0) + ", covering " + Range(exp) +
                     (lo < hi ? " (fewer than two experiment samples in the common range)" : "") +
                     "; both need a common time range in seconds: check that both time columns "
                     "start from the same origin in the same unit, and remove any start offset");
  }
  a.overlap_t0_s = exp.t_s[first];
  a.overlap_t1_s = exp.t_s[last - 1];
  a.samples = last - first;
  a.t_s.assign(exp.t_s.begin() + static_cast<std::ptrdiff_t>(first),
               exp.t_s.begin() + static_cast<std::ptrdiff_t>(last));
  a.y_exp.assign(exp.y.begin() + static_cast<std::ptrdiff_t>(first),
                 exp.y.begin() + static_cast<std::ptrdiff_t>(last));
  a.y_sim = a.same_time_base
                ? std::vector<double>(sim.y.begin() + static_cast<std::ptrdiff_t>(first),
                                      sim.y.begin() + static_cast<std::ptrdiff_t>(last))
                : InterpolateAt(sim.t_s, sim.y, a.t_s);
  if (!a.same_time_base) {
    a.notes.push_back("simulation resampled by linear interpolation onto the experiment's " +
                      std::to_string(a.samples) + " samples in the overlap [" +
                      Num(a.overlap_t0_s) + ", " + Num(a.overlap_t1_s) + "] s");
  }
  return {first, last};
}

// "FILE:LINE:COL" of sample `i` of `c` (column 0-based; 0 = time).
std::string Cell(const Curve& c, std::size_t i, std::size_t column) {
  return i < c.lines.size() ? CsvLocation(c.path, c.lines[i], column + 1) : c.path;
}

// Times and values beyond kMaxAssessedMagnitude would overflow the squares the scores sum.
void CheckMagnitudes(const Curve& c, AssessOption option, const char* role) {
  const auto beyond = [](double v) { return !(std::abs(v) <= kMaxAssessedMagnitude); };
  for (std::size_t i = 0; i < c.y.size(); ++i) {
    const bool time = i < c.t_s.size() && beyond(c.t_s[i]);
    if (!time && !beyond(c.y[i])) continue;
    throw OptionError(option, Cell(c, i, time ? 0 : c.column) + ": the " + role + " curve (" +
                                  c.label + ") holds " + (time ? "the time " : "") +
                                  Num(time ? c.t_s[i] : c.y[i]) + ", beyond +-" +
                                  Num(kMaxAssessedMagnitude) +
                                  ", the largest magnitude assess scores (its square leaves "
                                  "double precision); rescale the column (another unit)");
  }
}

// A constant experiment makes eps_t zero, and then no time-domain score exists; one that moves
// less than kMinAssessedRange squares every error to 0 and would score any simulation 1.
void RequireMovingExperiment(const Curve& exp, const Overlap& overlap, const Assessment& a) {
  const auto [lo_it, hi_it] = std::minmax_element(a.y_exp.begin(), a.y_exp.end());
  const std::string where = Lines(exp, overlap.first, overlap.last - 1, exp.column) +
                            ": the experiment curve (" + exp.label + ") ";
  if (!(*hi_it > *lo_it)) {
    throw OptionError(AssessOption::kExp,
                      where + "is constant (" + Num(*lo_it) +
                          ") over the compared range, so the error threshold eps_t = "
                          "Kp*(max - min) is 0 and no score exists; pick the column that moves");
  }
  if (*hi_it - *lo_it < kMinAssessedRange) {
    throw OptionError(AssessOption::kExp,
                      where + "moves by only " + Num(*hi_it - *lo_it) +
                          " over the compared range, less than " + Num(kMinAssessedRange) +
                          ", the smallest range assess scores (its errors would square to 0); "
                          "rescale the column (another unit)");
  }
}

// Both curves on one uniform grid: the delay, the spectra and ISO 18571 need one.
struct GridCurves {
  std::vector<double> t_s;
  std::vector<double> sim;
  std::vector<double> exp;
};

// The grid a time base that is not uniform is resampled onto must stay within
// kMaxGridPointsPerSample points per compared sample.
void CheckGridSize(const Curve& exp, const Overlap& overlap, const Assessment& a) {
  const double points = std::floor((a.overlap_t1_s - a.overlap_t0_s) / a.grid_step_s) + 1.0;
  const double most = static_cast<double>(kMaxGridPointsPerSample * a.samples);
  if (points <= most) return;
  throw OptionError(AssessOption::kExp,
                    Lines(exp, overlap.first, overlap.last - 1, 0) +
                        ": the time base is uneven: a uniform grid at its median step of " +
                        Num(a.grid_step_s) + " s over [" + Num(a.overlap_t0_s) + ", " +
                        Num(a.overlap_t1_s) + "] s would hold " + Num(points) +
                        " samples, more than " + std::to_string(kMaxGridPointsPerSample) +
                        " per compared sample (" + std::to_string(a.samples) +
                        "); resample the files onto one step, or remove the rows around the gap");
}

GridCurves OnUniformGrid(const Curve& sim, const Curve& exp, const Overlap& overlap,
                         Assessment& a) {
  a.grid_step_s = MedianStep(a.t_s);
  a.uniform_time_base = IsUniform(a.t_s);
  if (a.uniform_time_base) return {a.t_s, a.y_sim, a.y_exp};
  CheckGridSize(exp, overlap, a);
  GridCurves grid;
  grid.t_s = UniformGrid(a.overlap_t0_s, a.overlap_t1_s, a.grid_step_s);
  grid.sim = InterpolateAt(sim.t_s, sim.y, grid.t_s);
  grid.exp = InterpolateAt(exp.t_s, exp.y, grid.t_s);
  a.notes.push_back("time base not uniform: delay, spectra and ISO 18571 use a uniform grid of " +
                    Num(a.grid_step_s) + " s (the median step)");
  return grid;
}

void EstimateGridDelay(const GridCurves& grid, const AssessOptions& options, Assessment& a) {
  const double duration_s = a.overlap_t1_s - a.overlap_t0_s;
  const double max_delay_s = options.max_delay_s.value_or(0.1 * duration_s);
  if (grid.t_s.size() >= 4) {
    a.delay = EstimateDelay(grid.sim, grid.exp, a.grid_step_s, max_delay_s);
  }
  if (a.delay.at_search_limit) {
    a.notes.push_back("the delay estimate sits at the edge of the search range (+-" +
                      Num(max_delay_s) + " s); widen the search range" +
                      OptionHint(options.name_option, AssessOption::kMaxDelay));
  }
}

// The time-domain score against the simulation shifted by the estimated delay, over the
// experiment samples the shifted simulation still covers.
void ScoreCompensated(const Curve& sim, const Curve& exp, const Overlap& overlap,
                      const AssessOptions& options, Assessment& a) {
  std::vector<double> queries;
  std::vector<double> y_exp_used;
  a.y_sim_compensated.assign(a.samples, std::numeric_limits<double>::quiet_NaN());
  const double s_lo = sim.t_s.front();
  const double s_hi = sim.t_s.back();
  std::size_t first_used = exp.t_s.size();
  for (std::size_t i = 0; i < exp.t_s.size(); ++i) {
    const double q = exp.t_s[i] - a.delay.delay_s;
    if (q < s_lo || q > s_hi) continue;
    if (first_used == exp.t_s.size()) first_used = i;
    queries.push_back(q);
    y_exp_used.push_back(exp.y[i]);
  }
  if (queries.size() < 2) {
    a.time_compensated = a.time;
    return;
  }
  const std::vector<double> shifted = InterpolateAt(sim.t_s, sim.y, queries);
  const auto [clo, chi] = std::minmax_element(y_exp_used.begin(), y_exp_used.end());
  a.time_compensated = *chi > *clo ? ScoreTimeDomain(shifted, y_exp_used, options.params) : a.time;
  for (std::size_t k = 0; k < shifted.size(); ++k) {
    const std::size_t i = first_used + k;  // the used samples are contiguous
    if (i >= overlap.first && i < overlap.last) a.y_sim_compensated[i - overlap.first] = shifted[k];
  }
}

void ScorePerformanceDomain(const AssessOptions& options, Assessment& a) {
  std::size_t p_first = 0;
  std::size_t p_last = a.samples;
  if (options.segment) {
    std::tie(p_first, p_last) = Inside(a.t_s, options.segment->first, options.segment->second);
    if (p_last - p_first < 3) {
      throw OptionError(AssessOption::kSegment,
                        "segment " + FromTo(*options.segment, "s") + " holds " +
                            std::to_string(p_last - p_first) +
                            " samples of the compared range [" + Num(a.overlap_t0_s) + ", " +
                            Num(a.overlap_t1_s) + "] s; need at least 3 (start it at the step)");
    }
  }
  const auto count = p_last - p_first;
  const std::span<const double> t_seg(a.t_s.data() + p_first, count);
  const std::span<const double> sim_seg(a.y_sim.data() + p_first, count);
  const std::span<const double> exp_seg(a.y_exp.data() + p_first, count);
  if (count >= 3) {
    a.performance = ScorePerformance(t_seg, sim_seg, exp_seg, options.setpoint, options.params);
  }
  if (count < 3) {
    a.performance_note = "fewer than 3 samples to compare";
  } else if (!a.performance) {
    a.performance_note = "the experiment shows no step in [" + Num(t_seg.front()) + ", " +
                         Num(t_seg.back()) + "] s (final value equals initial value); " +
                         "choose the step's start and end times" +
                         OptionHint(options.name_option, AssessOption::kSegment);
  }
}

// A constant input excites no frequency, and one that moves less than kMinAssessedRange
// squares its spectra to 0. The message names the input samples the interpolation used: from
// the last one at or before the range's start to the first one at or after its end.
[[noreturn]] void ThrowConstantInput(const Curve& input, std::span<const double> g, double lo,
                                     double hi) {
  const auto& ut = input.t_s;
  const auto after_start = std::upper_bound(ut.begin(), ut.end(), g.front()) - ut.begin();
  const auto at_end = std::lower_bound(ut.begin(), ut.end(), g.back()) - ut.begin();
  const auto u_first = static_cast<std::size_t>(std::max<std::ptrdiff_t>(after_start - 1, 0));
  const auto u_last = std::min(static_cast<std::size_t>(at_end), ut.size() - 1);
  throw OptionError(AssessOption::kInput,
                    Lines(input, u_first, u_last, input.column) + ": the input curve (" +
                        input.label + ") " +
                        (hi > lo ? "moves by only " + Num(hi - lo) + ", less than " +
                                       Num(kMinAssessedRange) + ","
                                 : "is constant (" + Num(lo) + ")") +
                        " over the compared range [" + Num(g.front()) + ", " +
                        Num(g.back()) + "] s, so it excites no frequency" +
                        (hi > lo ? " assess can score; rescale the column (another unit)"
                                 : "; give the column that drove both systems"));
}

// The frequency domain needs the input the two systems were given.
void ScoreFrequencyDomain(const Curve* input, const GridCurves& grid,
                          const AssessOptions& options, Assessment& a) {
  if (input == nullptr) {
    a.frequency_note =
        "no input curve given" + OptionHint(options.name_option, AssessOption::kInput);
    return;
  }
  const double f_lo = std::max(grid.t_s.front(), input->t_s.front());
  const double f_hi = std::min(grid.t_s.back(), input->t_s.back());
  const auto [g_first, g_last] = Inside(grid.t_s, f_lo, f_hi);
  if (!(f_lo < f_hi) || g_last - g_first < 16) {
    throw OptionError(AssessOption::kInput,
                      "the input curve " + input->label + " covers " + Range(*input) +
                          ", which leaves fewer than 16 samples of the compared range [" +
                          Num(a.overlap_t0_s) + ", " + Num(a.overlap_t1_s) +
                          "] s; give the input that drove both runs");
  }
  const std::span<const double> g(grid.t_s.data() + g_first, g_last - g_first);
  const std::vector<double> u = InterpolateAt(input->t_s, input->y, g);
  const auto [ulo, uhi] = std::minmax_element(u.begin(), u.end());
  if (!(*uhi - *ulo >= kMinAssessedRange)) ThrowConstantInput(*input, g, *ulo, *uhi);
  const std::size_t segment =
      options.welch_segment > 0 ? options.welch_segment : DefaultWelchSegment(g.size());
  if (segment < 8 || segment > g.size()) {
    throw OptionError(AssessOption::kWelchSegment,
                      "Welch segment of " + std::to_string(segment) +
                          " samples: must lie in [8, " + std::to_string(g.size()) +
                          "] (the samples available)");
  }
  const std::span<const double> gs(grid.sim.data() + g_first, g.size());
  const std::span<const double> ge(grid.exp.data() + g_first, g.size());
  a.frequency = ScoreFrequency(
      u, gs, ge, a.grid_step_s, segment, options.coherence_min, options.params,
      a.frequency_note, options.band_hz ? options.band_hz->first : 0.0,
      options.band_hz ? options.band_hz->second : std::numeric_limits<double>::infinity(),
      options.name_option);
}

void CrossCheck(const GridCurves& grid, const AssessOptions& options, Assessment& a) {
  a.theil = TheilInequality(a.y_sim, a.y_exp);
  const std::vector<double>& t = grid.t_s;
  if (t.size() < 20) {
    // The rating's phase shift and moving averages need a record; a number would mislead.
    a.iso_note = "the compared range holds " + std::to_string(t.size()) +
                 " samples on the uniform grid; ISO/TS 18571 needs at least 20";
  } else if (t.size() > options.iso_max_samples && options.iso_max_samples >= 20) {
    const double step = (t.back() - t.front()) / static_cast<double>(options.iso_max_samples - 1);
    std::vector<double> coarse(options.iso_max_samples);
    for (std::size_t i = 0; i < coarse.size(); ++i) coarse[i] = t.front() + static_cast<double>(i) * step;
    coarse.back() = t.back();
    a.iso = Iso18571Rating(InterpolateAt(t, grid.exp, coarse), InterpolateAt(t, grid.sim, coarse));
  } else {
    a.iso = Iso18571Rating(grid.exp, grid.sim);
  }
}

// The total is the weighted mean of the domains that carry weight; a weighted domain that
// could not be computed is an error, not a silent zero.
void WeighTotal(const AssessOptions& options, Assessment& a) {
  const auto& w = options.weights;
  if (w[1] > 0.0 && !a.performance) {
    throw OptionError(AssessOption::kWeights, "the performance domain has weight " + Num(w[1]) +
                                                  " but cannot be computed: " +
                                                  a.performance_note);
  }
  if (w[2] > 0.0 && !a.frequency) {
    throw OptionError(AssessOption::kWeights, "the frequency domain has weight " + Num(w[2]) +
                                                  " but cannot be computed: " +
                                                  a.frequency_note);
  }
  const double eta_time = options.total_uses_compensated ? a.time_compensated.eta : a.time.eta;
  double sum = w[0] * eta_time;
  double weight = w[0];
  if (w[1] > 0.0) {
    sum += w[1] * a.performance->eta;
    weight += w[1];
  }
  if (w[2] > 0.0) {
    sum += w[2] * a.frequency->eta;
    weight += w[2];
  }
  a.total = sum / weight;
  a.pass = a.total >= options.params.eta_pass;
}

nlohmann::json InputsJson(const Assessment& a) {
  return {{"sim", a.sim_label},
          {"exp", a.exp_label},
          {"input", a.input_label.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.input_label)},
          {"same_time_base", a.same_time_base},
          {"overlap_s", {a.overlap_t0_s, a.overlap_t1_s}},
          {"samples", a.samples},
          {"step_s", a.grid_step_s},
          {"uniform_time_base", a.uniform_time_base}};
}

nlohmann::json ParametersJson(const AssessOptions& o) {
  return {{"kp", o.params.kp},
          {"eta_pass", o.params.eta_pass},
          {"weights", {{"time", o.weights[0]},
                       {"performance", o.weights[1]},
                       {"frequency", o.weights[2]}}},
          {"total_uses_compensated", o.total_uses_compensated}};
}

nlohmann::json DelayJson(const DelayEstimate& d) {
  return {{"delay_s", d.delay_s},
          {"samples", d.delay_samples},
          {"search_range_samples", d.max_lag_samples},
          {"at_search_limit", d.at_search_limit}};
}

nlohmann::json PerformanceJson(const std::optional<PerformanceScore>& performance) {
  if (!performance) return nullptr;
  const PerformanceScore& p = *performance;
  nlohmann::json metrics = nlohmann::json::object();
  for (const MetricScore& m : p.metrics) {
    metrics[m.name] = {{"sim", Opt(m.sim)},
                       {"exp", Opt(m.exp)},
                       {"scored", m.scored},
                       {"error", m.scored && m.sim && m.exp ? nlohmann::json(m.error) : nlohmann::json(nullptr)},
                       {"threshold", m.scored && m.sim && m.exp ? nlohmann::json(m.threshold) : nlohmann::json(nullptr)},
                       {"eta", m.scored ? nlohmann::json(m.eta) : nlohmann::json(nullptr)}};
  }
  return {{"segment_s", {p.t0_s, p.t1_s}},
          {"samples", p.samples},
          {"setpoint", p.setpoint},
          {"setpoint_given", p.setpoint_given},
          {"metrics", metrics},
          {"eta", p.eta}};
}

nlohmann::json FrequencyJson(const std::optional<FrequencyScore>& frequency) {
  if (!frequency) return nullptr;
  const FrequencyScore& f = *frequency;
  return {{"welch_segment_samples", f.segment_samples},
          {"welch_segments", f.segments},
          {"welch_segments_total", f.segments_total},
          {"coherence_min", f.coherence_min},
          {"input_power_min_fraction", kInputPowerFraction},
          {"bins_used", f.bins_used},
          {"bins_low_input", f.bins_low_input},
          {"bins_total", f.bins_total},
          {"band_hz", {f.f_min_hz, f.f_max_hz}},
          {"magnitude_db", DomainJson(f.magnitude)},
          {"phase_deg", DomainJson(f.phase)},
          {"eta", f.eta}};
}

nlohmann::json NotComputedJson(const Assessment& a) {
  nlohmann::json why = nlohmann::json::object();
  if (!a.performance) why["performance_domain"] = a.performance_note;
  if (!a.frequency) why["frequency_domain"] = a.frequency_note;
  if (!a.iso) why["iso18571"] = a.iso_note;
  return why;
}

nlohmann::json CrossChecksJson(const Assessment& a) {
  return {
      {"theil", {{"u", a.theil.u}, {"bias", a.theil.bias}, {"variance", a.theil.variance},
                 {"covariance", a.theil.covariance}}},
      {"iso18571", a.iso ? nlohmann::json{{"corridor", a.iso->corridor},
                                          {"phase", a.iso->phase},
                                          {"magnitude", a.iso->magnitude},
                                          {"slope", a.iso->slope},
                                          {"overall", a.iso->overall},
                                          {"grade", a.iso->grade},
                                          {"phase_shift_samples", a.iso->phase_shift_samples},
                                          {"samples", a.iso->samples}}
                         : nlohmann::json(nullptr)}};
}

}  // namespace

Assessment Assess(const Curve& sim, const Curve& exp, const Curve* input,
                  const AssessOptions& options) {
  CheckOptions(options);
  CheckMagnitudes(sim, AssessOption::kSim, "simulation");
  CheckMagnitudes(exp, AssessOption::kExp, "experiment");
  if (input != nullptr) CheckMagnitudes(*input, AssessOption::kInput, "input");
  Assessment a;
  a.options = options;
  a.sim_label = sim.label;
  a.exp_label = exp.label;
  if (input != nullptr) a.input_label = input->label;
  a.same_time_base = sim.t_s == exp.t_s;

  const Overlap overlap = AlignOnOverlap(sim, exp, a);
  RequireMovingExperiment(exp, overlap, a);
  a.time = ScoreTimeDomain(a.y_sim, a.y_exp, options.params);
  const GridCurves grid = OnUniformGrid(sim, exp, overlap, a);
  EstimateGridDelay(grid, options, a);
  ScoreCompensated(sim, exp, overlap, options, a);
  ScorePerformanceDomain(options, a);
  ScoreFrequencyDomain(input, grid, options, a);
  CrossCheck(grid, options, a);
  WeighTotal(options, a);
  return a;
}

nlohmann::json ToJson(const Assessment& a) {
  nlohmann::json j;
  j["inputs"] = InputsJson(a);
  j["parameters"] = ParametersJson(a.options);
  j["time_domain"] = TimeJson(a.time);
  j["delay_s"] = a.delay.delay_s;
  j["delay"] = DelayJson(a.delay);
  j["time_domain_compensated"] = TimeJson(a.time_compensated);
  j["performance_domain"] = PerformanceJson(a.performance);
  j["frequency_domain"] = FrequencyJson(a.frequency);
  j["not_computed"] = NotComputedJson(a);
  j["cross_checks"] = CrossChecksJson(a);
  j["notes"] = a.notes;
  j["total"] = a.total;
  j["pass"] = a.pass;
  j["verdict"] = a.pass ? "PASS" : "FAIL";
  return j;
}

std::string FormatText(const Assessment& a) {
  std::string out;
  out += "hiltwin assess: credibility of the simulation against the experiment (thesis 2.4)\n";
  out += "  simulation  y_s: " + a.sim_label + "\n";
  out += "  experiment  y_e: " + a.exp_label + "\n";
  if (!a.input_label.empty()) out += "  input       u  : " + a.input_label + "\n";
  out += Format("  compared over %.6g .. %.6g s, %zu samples%s (step %.6g s)\n", a.overlap_t0_s,
                a.overlap_t1_s, a.samples, a.same_time_base ? ", one time base" : "", a.grid_step_s);
  out += Format("  Kp = %.6g, eta_pass = %.6g, weights time,perf,freq = %.6g,%.6g,%.6g\n\n",
                a.options.params.kp, a.options.params.eta_pass, a.options.weights[0],
                a.options.weights[1], a.options.weights[2]);

  out += "Time domain (appendix C)                          raw            delay-compensated\n";
  out += Format("  e_t   = RMS(y_e - y_s)                      %-14.6g %-14.6g\n", a.time.e_t,
                a.time_compensated.e_t);
  out += Format("  eps_t = Kp * (max y_e - min y_e)            %-14.6g %-14.6g\n", a.time.eps_t,
                a.time_compensated.eps_t);
  out += Format("  K_e   = eta_pass / sqrt(1 - eta_pass^2)     %-14.6g %-14.6g\n", a.time.k_e,
                a.time_compensated.k_e);
  out += Format("  eta   = K_e*eps_t / sqrt((K_e*eps_t)^2 + e_t^2)\n"
                "                                              %-8.6f %5.1f %%  %-8.6f %5.1f %%\n",
                a.time.eta, 100.0 * a.time.eta, a.time_compensated.eta,
                100.0 * a.time_compensated.eta);
  out += Format("  delay d = %.6g s (%.3f samples), y_e(t) ~ y_s(t - d); search +-%zu samples\n\n",
                a.delay.delay_s, a.delay.delay_samples, a.delay.max_lag_samples);

  if (a.performance) {
    const PerformanceScore& p = *a.performance;
    out += Format("Performance domain (step response over %.6g .. %.6g s, setpoint %.6g%s)\n",
                  p.t0_s, p.t1_s, p.setpoint, p.setpoint_given ? "" : " = experiment's final value");
    out += "  metric                    sim            exp            |error|        threshold      eta\n";
    for (const MetricScore& m : p.metrics) {
      const bool both = m.sim && m.exp;
      out += Format("  %-24s  %-14s %-14s %-14s %-14s %s\n", m.label.c_str(), OptText(m.sim).c_str(),
                    OptText(m.exp).c_str(), both ? Num(m.error).c_str() : "-",
                    both ? Num(m.threshold).c_str() : "-",
                    m.scored ? Format("%.4f", m.eta).c_str() : "not scored");
    }
    out += Format("  domain score (mean)                                                                %.4f\n\n",
                  p.eta);
  } else {
    out += "Performance domain: not computed: " + a.performance_note + "\n\n";
  }

  if (a.frequency) {
    const FrequencyScore& f = *a.frequency;
    out += Format("Frequency domain (Welch, %zu-sample Hann segments: %zu of %zu carry input)\n",
                  f.segment_samples, f.segments, f.segments_total);
    out += Format("  bins used: %zu of %zu, %.4g .. %.4g Hz (input power >= %.3g of the peak: "
                  "%zu below; then coherence > %.2g for both)\n",
                  f.bins_used, f.bins_total, f.f_min_hz, f.f_max_hz, kInputPowerFraction,
                  f.bins_low_input, f.coherence_min);
    out += Format("  magnitude  e = %-10.4g dB  eps = %-8.4g dB   eta = %.4f\n", f.magnitude.e,
                  f.magnitude.eps, f.magnitude.eta);
    out += Format("  phase      e = %-10.4g deg eps = %-8.4g deg  eta = %.4f\n", f.phase.e,
                  f.phase.eps, f.phase.eta);
    out += Format("  domain score (mean)                          %.4f\n\n", f.eta);
  } else {
    out += "Frequency domain: not computed: " + a.frequency_note + "\n\n";
  }

  out += "Cross-checks (not part of the total)\n";
  out += Format("  Theil U = %.4g (0 = identical); MSE split: bias %.3f, variance %.3f, covariance %.3f\n",
                a.theil.u, a.theil.bias, a.theil.variance, a.theil.covariance);
  if (a.iso) {
    out += Format("  ISO/TS 18571: corridor %.3f, phase %.3f, magnitude %.3f, slope %.3f"
                  " -> %.3f (%s)\n\n",
                  a.iso->corridor, a.iso->phase, a.iso->magnitude, a.iso->slope, a.iso->overall,
                  a.iso->grade.c_str());
  } else {
    out += "  ISO/TS 18571: not computed: " + a.iso_note + "\n\n";
  }
  for (const std::string& note : a.notes) out += "note: " + note + "\n";
  if (!a.notes.empty()) out += "\n";
  out += Format("Total = %.6f (%.1f %%)%s  %s eta_pass %.6g  ->  %s\n", a.total, 100.0 * a.total,
                a.options.total_uses_compensated ? " [delay-compensated time score]" : "",
                a.pass ? ">=" : "<", a.options.params.eta_pass, a.pass ? "PASS" : "FAIL");
  return out;
}

}  // namespace hiltwin::analysis
