#pragma once
/// Frequency responses by Welch's method (FFTW) and the frequency-domain score.

#include <complex>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/assess/assess_option.h"
#include "hiltwin/assess/credibility.h"

namespace hiltwin::analysis {

/// A bin or Welch segment whose input power is below this fraction of the largest carries
/// no usable input [hiltwin]: noise-free data keep the coherence near 1 even there, so the
/// coherence gate alone would let rounding-level responses into the score.
inline constexpr double kInputPowerFraction = 1e-3;

/// Fewest Welch segments with input power for a frequency-domain score [hiltwin]: with one
/// segment the coherence estimate is 1 whatever the data, and it stays biased upwards for few.
inline constexpr std::size_t kMinInputSegments = 4;

/// H1 estimate of the response from u to y with its magnitude-squared coherence, one value
/// per frequency bin from 0 to the Nyquist frequency.
struct FrequencyResponse {
  std::vector<double> frequency_hz;
  std::vector<std::complex<double>> h;  ///< P_uy / P_uu
  std::vector<double> coherence;        ///< |P_uy|² / (P_uu·P_yy), 0 where undefined
  std::vector<double> input_power;      ///< P_uu (summed over segments, unscaled)
  std::size_t segments = 0;             ///< number of averaged segments
  /// Segments whose windowed, detrended input energy is at least kInputPowerFraction of the
  /// largest segment's (a step input moves only the few segments that hold the step).
  std::size_t segments_with_input = 0;
};

/// Welch's method: Hann-windowed segments of `segment_samples` with 50 % overlap, each with
/// its least-squares line removed. u and y on one uniform grid of `step_s`. Throws
/// std::invalid_argument for mismatched lengths or a segment longer than the data or < 8.
[[nodiscard]] FrequencyResponse EstimateFrequencyResponse(std::span<const double> u,
                                                          std::span<const double> y,
                                                          double step_s,
                                                          std::size_t segment_samples);

/// Default Welch segment: the largest power of two ≤ n/8, clamped to [16, 65536].
[[nodiscard]] std::size_t DefaultWelchSegment(std::size_t n);

/// Frequency-domain score: magnitude (dB) and phase (degrees) errors over the bins with input
/// power (≥ kInputPowerFraction of the largest bin's) where both coherences exceed the
/// threshold, each mapped through the η function; η_f is their mean.
struct FrequencyScore {
  std::size_t segment_samples = 0;
  std::size_t segments = 0;        ///< segments that carry input power (see FrequencyResponse)
  std::size_t segments_total = 0;  ///< all Welch segments
  std::size_t bins_used = 0;
  std::size_t bins_total = 0;      ///< bins above DC
  std::size_t bins_low_input = 0;  ///< in the band, dropped for too little input power
  double f_min_hz = 0.0;
  double f_max_hz = 0.0;
  double coherence_min = 0.8;
  DomainScore magnitude;  ///< e = RMS of 20·log10|H_s/H_e| [dB], ε = 20·log10(1 + Kp)
  DomainScore phase;      ///< e = RMS of arg(H_s/H_e) [deg], ε = Kp·180°
  double eta = 0.0;
};

/// Uses bins in [band_lo_hz, band_hi_hz] only. Returns nullopt (with `why` filled) when fewer
/// than kMinInputSegments segments carry input power or no bin passes both gates; `why`
/// names the options to change through `name_option`.
[[nodiscard]] std::optional<FrequencyScore> ScoreFrequency(
    std::span<const double> u, std::span<const double> y_sim, std::span<const double> y_exp,
    double step_s, std::size_t segment_samples, double coherence_min,
    const CredibilityParams& params, std::string& why, double band_lo_hz = 0.0,
    double band_hi_hz = std::numeric_limits<double>::infinity(),
    OptionNamer name_option = NoOptionNames);

}  // namespace hiltwin::analysis
