// ns per QosMonitor::Record() for the default rules and for a 1000-cycle window, against a
// naive peer that recounts the window from a ring of flags on every cycle (O(k)). Best of
// several repetitions, because the machine is shared; the miss pattern is fixed (1 % random,
// seeded) and pre-generated so that only the monitor is timed.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string_view>
#include <vector>

#include "hiltwin/qos/monitor.h"

namespace {

using Clock = std::chrono::steady_clock;

std::vector<bool> Pattern(std::size_t length) {
  std::mt19937 rng(42);
  std::bernoulli_distribution miss(0.01);
  std::vector<bool> seq(length);
  for (std::size_t i = 0; i < length; ++i) seq[i] = miss(rng);
  return seq;
}

// The straightforward implementation: keep the last k flags, recount them every cycle.
class NaiveWindow {
 public:
  NaiveWindow(std::uint32_t m, std::uint32_t k) : m_(m), flags_(k, false) {}
  bool Record(bool missed) noexcept {
    flags_[next_] = missed;
    next_ = next_ + 1 == flags_.size() ? 0 : next_ + 1;
    std::uint32_t met = 0;
    for (bool f : flags_) met += f ? 0U : 1U;
    violations_ += met < m_ ? 1U : 0U;
    return met < m_;
  }
  [[nodiscard]] std::uint64_t violations() const noexcept { return violations_; }

 private:
  std::uint32_t m_;
  std::vector<bool> flags_;
  std::size_t next_ = 0;
  std::uint64_t violations_ = 0;
};

template <typename Fn>
double BestNsPerCall(std::size_t calls, int repetitions, Fn&& run) {
  double best = 1e300;
  for (int r = 0; r < repetitions; ++r) {
    const auto start = Clock::now();
    run(calls);
    const auto end = Clock::now();
    const double ns = std::chrono::duration<double, std::nano>(end - start).count();
    best = std::min(best, ns / static_cast<double>(calls));
  }
  return best;
}

double TimeMonitor(const std::vector<hiltwin::qos::RuleSpec>& rules, const std::vector<bool>& seq,
                   int repetitions, std::uint64_t& sink, std::uint64_t planned_cycles = 0) {
  return BestNsPerCall(seq.size(), repetitions, [&](std::size_t calls) {
    hiltwin::qos::QosMonitor monitor(
        hiltwin::qos::QosConfig{.rules = rules, .planned_cycles = planned_cycles});
    for (std::size_t i = 0; i < calls; ++i) sink += monitor.Record(i, seq[i]) ? 1U : 0U;
    sink += monitor.misses() + monitor.DistanceToFailure();
  });
}

double TimeNaive(std::uint32_t m, std::uint32_t k, const std::vector<bool>& seq, int repetitions,
                 std::uint64_t& sink) {
  return BestNsPerCall(seq.size(), repetitions, [&](std::size_t calls) {
    NaiveWindow naive(m, k);
    for (std::size_t i = 0; i < calls; ++i) sink += naive.Record(seq[i]) ? 1U : 0U;
    sink += naive.violations();
  });
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t cycles = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 2'000'000UL;
  const int repetitions = 5;
  std::uint64_t sink = 0;
  if (argc > 2 && std::string_view(argv[2]) == "--once") {
    // A fixed-size pattern, reused, so that its generation is set-up cost that cancels.
    const std::vector<bool> pattern = Pattern(1U << 16);
    // For callgrind (callgrind_record.sh): one pass of the default rules with a plan, no
    // timing, so instructions per Record() = (I(n2) - I(n1)) / (n2 - n1).
    hiltwin::qos::QosMonitor monitor(
        hiltwin::qos::QosConfig{.rules = hiltwin::qos::DefaultRules(), .planned_cycles = cycles});
    for (std::size_t i = 0; i < cycles; ++i) {
      sink += monitor.Record(i, pattern[i & 0xFFFFU]) ? 1U : 0U;
    }
    std::printf("cycles=%zu misses=%llu sink=%llu\n", cycles,
                static_cast<unsigned long long>(monitor.misses()),
                static_cast<unsigned long long>(sink));
    return 0;
  }
  const std::vector<bool> seq = Pattern(cycles);
  using hiltwin::qos::MakeConsecutiveMissesRule;
  using hiltwin::qos::MakeMissRatioRule;
  using hiltwin::qos::MakeMkRule;

  const double defaults_ns = TimeMonitor(hiltwin::qos::DefaultRules(), seq, repetitions, sink);
  const double planned_ns =
      TimeMonitor(hiltwin::qos::DefaultRules(), seq, repetitions, sink, cycles);
  const double naive4_ns = TimeNaive(3, 4, seq, repetitions, sink);
  const double k1000_ns = TimeMonitor({MakeMkRule(990, 1000)}, seq, repetitions, sink);
  const double naive1000_ns = TimeNaive(990, 1000, seq, repetitions, sink);
  const double full_ns = TimeMonitor({MakeMissRatioRule(1.0), MakeMkRule(3, 4),
                                      MakeMkRule(990, 1000), MakeConsecutiveMissesRule(3)},
                                     seq, repetitions, sink);

  std::printf("QoS Record(), %zu cycles, 1 %% random misses, best of %d\n", cycles, repetitions);
  std::printf(
      "  default rules (<1 %%, (3,4)):      %6.2f ns/cycle  | naive (3,4) recount:    "
      "%6.2f ns  ratio %.2f\n",
      defaults_ns, naive4_ns, defaults_ns / naive4_ns);
  std::printf(
      "  default rules, planned run:         %6.2f ns/cycle  (hiltwin run passes the "
      "plan)\n",
      planned_ns);
  std::printf(
      "  (990,1000)-firm:                   %6.2f ns/cycle  | naive (990,1000) recount: "
      "%6.2f ns  ratio %.3f\n",
      k1000_ns, naive1000_ns, k1000_ns / naive1000_ns);
  std::printf("  4 rules (<1 %%, (3,4), (990,1000), <=3 consecutive): %6.2f ns/cycle\n", full_ns);
  std::printf("  (sink %llu)\n", static_cast<unsigned long long>(sink));
  return 0;
}
