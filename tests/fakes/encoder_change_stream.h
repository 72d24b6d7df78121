#pragma once
// Random encoder position changes as in the thesis's reliability test (Table 5.2): mostly small,
// some large, some at the pulse limit, every tenth a hard reversal of the previous change. Used
// by the 720,000-message tests through the board model and through the RTL.

#include <cstdint>
#include <random>

namespace hiltwin::test {

class EncoderChangeStream {
 public:
  /// `limit`: the largest change one period can emit (io::MaxCountsPerStep).
  EncoderChangeStream(std::uint64_t seed, std::int64_t limit) : rng_(seed), large_(-limit, limit) {}

  std::int64_t Next() {
    const int roll = kind_(rng_);
    std::int64_t change = 0;
    if (roll < 94) {
      change = small_(rng_);
    } else if (roll < 99) {
      change = large_(rng_) / 4;
    } else {
      change = large_(rng_);
    }
    if (roll % 10 == 0) change = -previous_;
    previous_ = change;
    return change;
  }

 private:
  std::mt19937_64 rng_;
  std::uniform_int_distribution<std::int64_t> small_{-100, 100};
  std::uniform_int_distribution<std::int64_t> large_;
  std::uniform_int_distribution<int> kind_{0, 99};
  std::int64_t previous_ = 0;
};

}  // namespace hiltwin::test
