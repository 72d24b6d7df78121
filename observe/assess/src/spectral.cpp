#include "hiltwin/assess/spectral.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "fftw_util.h"

namespace hiltwin::analysis {
namespace {

// Removes the least-squares line from seg (positions and ramps would otherwise leak
// their trend into every bin of an integrating plant's response).
void Detrend(std::vector<double>& seg) {
  const auto n = static_cast<double>(seg.size());
  const double mean_i = (n - 1.0) / 2.0;
  double mean_v = 0.0;
  for (const double v : seg) mean_v += v;
  mean_v /= n;
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    const double di = static_cast<double>(i) - mean_i;
    sxy += di * (seg[i] - mean_v);
    sxx += di * di;
  }
  const double slope = sxx > 0.0 ? sxy / sxx : 0.0;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    seg[i] -= mean_v + slope * (static_cast<double>(i) - mean_i);
  }
}

std::string G(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace

std::size_t DefaultWelchSegment(std::size_t n) {
  std::size_t seg = 16;
  while (seg * 2 <= n / 8 && seg < 65536) seg *= 2;
  return seg;
}

FrequencyResponse EstimateFrequencyResponse(std::span<const double> u, std::span<const double> y,
                                            double step_s, std::size_t segment_samples) {
  if (u.size() != y.size()) throw std::invalid_argument("Welch: input and output differ in length");
  if (segment_samples < 8 || segment_samples > u.size()) {
    throw std::invalid_argument("Welch: segment must hold 8 .. n samples");
  }
  if (!(step_s > 0.0)) throw std::invalid_argument("Welch: step must be positive");
  const std::size_t len = segment_samples;
  const std::size_t hop = len / 2;
  const std::size_t bins = len / 2 + 1;
  std::vector<double> window(len);
  for (std::size_t i = 0; i < len; ++i) {
    window[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                     static_cast<double>(len));
  }
  detail::RealBuffer real(len);
  detail::ComplexBuffer spec(bins);
  const detail::FftwPlan plan(
      fftw_plan_dft_r2c_1d(static_cast<int>(len), real.data(), spec.data(), FFTW_ESTIMATE));
  std::vector<double> puu(bins, 0.0);
  std::vector<double> pyy(bins, 0.0);
  std::vector<std::complex<double>> puy(bins, {0.0, 0.0});
  std::vector<std::complex<double>> uf(bins);
  std::vector<double> seg(len);
  std::vector<double> segment_input_energy;
  FrequencyResponse response;
  for (std::size_t start = 0; start + len <= u.size(); start += hop) {
    for (int pass = 0; pass < 2; ++pass) {
      const std::span<const double> source = pass == 0 ? u : y;
      std::copy(source.begin() + static_cast<std::ptrdiff_t>(start),
                source.begin() + static_cast<std::ptrdiff_t>(start + len), seg.begin());
      Detrend(seg);
      double energy = 0.0;
      for (std::size_t i = 0; i < len; ++i) {
        real[i] = seg[i] * window[i];
        energy += real[i] * real[i];
      }
      if (pass == 0) segment_input_energy.push_back(energy);
      plan.Execute();
      for (std::size_t b = 0; b < bins; ++b) {
        const std::complex<double> value = detail::ToComplex(spec[b]);
        if (pass == 0) {
          uf[b] = value;
          puu[b] += std::norm(value);
        } else {
          pyy[b] += std::norm(value);
          puy[b] += std::conj(uf[b]) * value;
        }
      }
    }
    ++response.segments;
  }
  const double max_energy =
      *std::max_element(segment_input_energy.begin(), segment_input_energy.end());
  response.segments_with_input = static_cast<std::size_t>(std::count_if(
      segment_input_energy.begin(), segment_input_energy.end(),
      [&](double e) { return e > 0.0 && e >= kInputPowerFraction * max_energy; }));
  response.input_power = puu;
  response.frequency_hz.resize(bins);
  response.h.resize(bins);
  response.coherence.resize(bins);
  const double fs_hz = 1.0 / step_s;
  for (std::size_t b = 0; b < bins; ++b) {
    response.frequency_hz[b] = static_cast<double>(b) * fs_hz / static_cast<double>(len);
    response.h[b] = puu[b] > 0.0 ? puy[b] / puu[b] : std::complex<double>(0.0, 0.0);
    const double denom = puu[b] * pyy[b];
    response.coherence[b] = denom > 0.0 ? std::norm(puy[b]) / denom : 0.0;
  }
  return response;
}

std::optional<FrequencyScore> ScoreFrequency(std::span<const double> u,
                                             std::span<const double> y_sim,
                                             std::span<const double> y_exp, double step_s,
                                             std::size_t segment_samples, double coherence_min,
                                             const CredibilityParams& params, std::string& why,
                                             double band_lo_hz, double band_hi_hz,
                                             OptionNamer name_option) {
  const FrequencyResponse sim = EstimateFrequencyResponse(u, y_sim, step_s, segment_samples);
  const FrequencyResponse exp = EstimateFrequencyResponse(u, y_exp, step_s, segment_samples);
  FrequencyScore score;
  score.segment_samples = segment_samples;
  score.segments = exp.segments_with_input;
  score.segments_total = exp.segments;
  score.coherence_min = coherence_min;
  score.bins_total = exp.h.size() - 1;  // DC is never used
  const std::string segments_text = std::to_string(score.segments) + " of " +
                                    std::to_string(score.segments_total) + " Welch segments (" +
                                    std::to_string(segment_samples) + " samples each)";
  if (score.segments < kMinInputSegments) {
    why = "only " + segments_text + " carry input power (>= " + G(kInputPowerFraction) +
          " of the largest segment's); need at least " + std::to_string(kMinInputSegments) +
          " for a coherence estimate; " +
          (score.segments_total < kMinInputSegments
               ? "use shorter Welch segments" +
                     OptionHint(name_option, AssessOption::kWelchSegment) + " or a longer record"
               : std::string("give an input that keeps changing (noise, a chirp, or many "
                             "steps: a step excites only the two segments around it, whatever "
                             "the Welch segment length)"));
    return std::nullopt;
  }
  // Bins the input hardly excites are dropped before the coherence gate: on noise-free data
  // their coherence is ~1 too, but their response is rounding or quantisation residue.
  const double max_input =
      *std::max_element(exp.input_power.begin() + 1, exp.input_power.end());
  double sum_mag = 0.0;
  double sum_phase = 0.0;
  std::size_t in_band = 0;
  for (std::size_t b = 1; b < exp.h.size(); ++b) {
    if (exp.frequency_hz[b] < band_lo_hz || exp.frequency_hz[b] > band_hi_hz) continue;
    ++in_band;
    if (!(exp.input_power[b] >= kInputPowerFraction * max_input && max_input > 0.0)) {
      ++score.bins_low_input;
      continue;
    }
    if (!(sim.coherence[b] > coherence_min && exp.coherence[b] > coherence_min)) continue;
    if (std::abs(sim.h[b]) == 0.0 || std::abs(exp.h[b]) == 0.0) continue;
    const std::complex<double> ratio = sim.h[b] / exp.h[b];
    const double mag_db = 20.0 * std::log10(std::abs(ratio));
    const double phase_deg = std::arg(ratio) * 180.0 / std::numbers::pi;
    sum_mag += mag_db * mag_db;
    sum_phase += phase_deg * phase_deg;
    if (score.bins_used == 0) score.f_min_hz = exp.frequency_hz[b];
    score.f_max_hz = exp.frequency_hz[b];
    ++score.bins_used;
  }
  if (score.bins_used == 0) {
    why = "no frequency bin has both input power (>= " + G(kInputPowerFraction) +
          " of the largest bin's) and coherence above " + G(coherence_min) +
          " for both curves (" + std::to_string(in_band) + " bins in the band " + G(band_lo_hz) +
          " .. " + G(band_hi_hz) + " Hz, " + std::to_string(score.bins_low_input) +
          " with too little input power; " + segments_text +
          "); excite the system more broadly, record longer, or change the Welch segment length" +
          OptionHint(name_option, AssessOption::kWelchSegment) + " or the band" +
          OptionHint(name_option, AssessOption::kBand);
    return std::nullopt;
  }
  const auto used = static_cast<double>(score.bins_used);
  const double k_e = NormalisationFactor(params.eta_pass);
  score.magnitude = {std::sqrt(sum_mag / used), 20.0 * std::log10(1.0 + params.kp), k_e, 0.0};
  score.phase = {std::sqrt(sum_phase / used), params.kp * 180.0, k_e, 0.0};
  score.magnitude.eta =
      CredibilityScore(score.magnitude.e, score.magnitude.eps, params.eta_pass);
  score.phase.eta = CredibilityScore(score.phase.e, score.phase.eps, params.eta_pass);
  score.eta = 0.5 * (score.magnitude.eta + score.phase.eta);
  return score;
}

}  // namespace hiltwin::analysis
