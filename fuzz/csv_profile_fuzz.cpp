// CSV input profiles (`hiltwin run --input FILE`, relbot/input_profile.h) and setpoint
// profiles (`hiltwin ecs --setpoints FILE`, setpoint_profile.h). Both parsers document
// ProfileError only; a profile they accept is then played (At() is noexcept and must give
// finite values within the documented range).
//
// Input: byte 0 chooses the reader (bit 0: setpoints); the rest is the CSV text.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_util.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/setpoint_profile.h"

namespace {

using namespace hiltwin::app;

/// Times to sample a profile of length `length_s` at: inside, at and past its ends.
constexpr double kFractions[] = {-1.0, 0.0, 0.25, 0.5, 0.999, 1.0, 1.5, 7.25};

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "FINDING: %s\n", what);
    std::abort();
  }
}

void PlayDuty(const InputProfile& profile) {
  for (const double f : kFractions) {
    const Duty duty = profile.At(f * profile.period_s());
    Require(std::isfinite(duty.left) && std::isfinite(duty.right) && std::abs(duty.left) <= 1.0 &&
                std::abs(duty.right) <= 1.0,
            "an accepted input profile plays a duty outside [-1, 1]");
  }
  (void)profile.At(std::nan(""));
}

void PlaySetpoints(const SetpointProfile& profile) {
  for (const double f : kFractions) {
    const WheelPositions p = profile.At(f * profile.length_s());
    Require(std::isfinite(p.left_m) && std::isfinite(p.right_m),
            "an accepted setpoint profile plays a non-finite position");
  }
  (void)profile.At(std::nan(""));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool setpoints = (data[0] & 1U) != 0;
  const auto text = hiltwin::fuzz::AsText(data + 1, size - 1);
  try {
    if (setpoints) {
      PlaySetpoints(ParseCsvSetpoints(text, "fuzz.csv"));
    } else {
      PlayDuty(ParseCsvProfile(text, "fuzz.csv"));
    }
  } catch (const ProfileError&) {
  }
  HILTWIN_FUZZ_UNDOCUMENTED(setpoints ? "ParseCsvSetpoints" : "ParseCsvProfile")
  return 0;
}
