#pragma once
/// The choices of an assessment that a message can concern. The library describes domain
/// values ("segment 5 s to 2 s: ..."); a command line maps each choice to its own flag.

#include <string>
#include <string_view>

#include "hiltwin/tracing/csv.h"

namespace hiltwin::analysis {

/// One field of AssessOptions, or one of the curves given to Assess.
enum class AssessOption {
  kSim,           ///< the simulation curve
  kExp,           ///< the experiment curve
  kInput,         ///< the input curve (frequency domain)
  kKp,            ///< CredibilityParams::kp
  kEtaPass,       ///< CredibilityParams::eta_pass
  kWeights,       ///< AssessOptions::weights
  kSegment,       ///< AssessOptions::segment
  kMaxDelay,      ///< AssessOptions::max_delay_s
  kWelchSegment,  ///< AssessOptions::welch_segment
  kCoherence,     ///< AssessOptions::coherence_min
  kBand,          ///< AssessOptions::band_hz
};

/// Names an option where library advice points to it; "" adds nothing to the domain wording.
using OptionNamer = std::string_view (*)(AssessOption option);

/// The library's own namer: domain wording only, no option names.
[[nodiscard]] inline std::string_view NoOptionNames(AssessOption /*option*/) { return {}; }

/// " (NAME)" with the name `namer` gives `option`, or "" when it gives none.
[[nodiscard]] inline std::string OptionHint(OptionNamer namer, AssessOption option) {
  const std::string_view name = namer != nullptr ? namer(option) : std::string_view{};
  return name.empty() ? std::string() : " (" + std::string(name) + ")";
}

/// A bad option value, or a curve that cannot serve. what() describes the domain value and
/// what to do; option() says which choice it concerns, so a command line can name its flag.
class OptionError : public InputError {
 public:
  OptionError(AssessOption option, const std::string& message)
      : InputError(message), option_(option) {}
  /// The choice the message is about.
  [[nodiscard]] AssessOption option() const noexcept { return option_; }

 private:
  AssessOption option_;
};

}  // namespace hiltwin::analysis
