// Wake-up latency of the hiltwin executive against cyclictest (rt-tests), alternating in the
// same run at each rate, both at SCHED_FIFO with locked memory. cyclictest is the reference a
// real-time engineer trusts; the executive should add nothing measurable on top of the
// absolute clock_nanosleep both use. Usage:
//   hiltwin_bench_latency [--rates 1000,4000,10000,20000] [--seconds 10] [--priority 90] [--rounds 5]
// Each round runs both once per rate; the median p99 ratio over the rounds is the figure, so
// one hypervisor stall in one run does not decide it.
// Misses are counted the same way for both: a wake-up later than one period after release,
// with the periods a stall swallowed skipped on both sides (the executive's own deadline-miss
// count, end > release + period plus skipped releases, is printed too).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/scheduler/executive.h"

namespace {

using hiltwin::kernel_glue::TimeNs;

struct LatencyFigures {
  double min_us = 0, avg_us = 0, p99_us = 0, p999_us = 0, max_us = 0;
  std::uint64_t samples = 0;
  std::uint64_t late = 0;  // wake-up later than one period
  std::uint64_t deadline_misses = 0;  // executive only
};

class NoopTask final : public hiltwin::scheduler::CyclicTask {
 public:
  hiltwin::scheduler::CycleAction Step(const hiltwin::scheduler::CycleContext&) noexcept override {
    return hiltwin::scheduler::CycleAction::kContinue;
  }
};

class LateCounter final : public hiltwin::scheduler::CycleObserver {
 public:
  explicit LateCounter(TimeNs period_ns) : period_ns_(period_ns) {}
  hiltwin::scheduler::CycleAction OnCycle(const hiltwin::scheduler::TimingSample& s) noexcept override {
    if (s.wake_ns - s.release_ns > period_ns_) ++late;
    misses += (s.missed ? 1U : 0U) + s.releases_skipped;  // as the QoS ledger counts them
    return hiltwin::scheduler::CycleAction::kContinue;
  }
  std::uint64_t late = 0;
  std::uint64_t misses = 0;

 private:
  TimeNs period_ns_;
};

LatencyFigures RunHiltwin(double rate_hz, double seconds) {
  hiltwin::kernel_glue::MonotonicClock clock;
  hiltwin::scheduler::ExecutiveConfig config;
  config.period_ns = hiltwin::kernel_glue::PeriodNsFromRateHz(rate_hz);
  config.max_cycles = static_cast<std::uint64_t>(rate_hz * seconds);
  // cyclictest skips the periods that passed while it was held up (its `while (now > next)
  // next += interval`), so one stall is one late wake-up there. The executive's kSkip policy
  // does the same; catch-up would add a late start for every period of the stall.
  config.overrun_policy = hiltwin::scheduler::OverrunPolicy::kSkip;
  hiltwin::scheduler::Executive executive(clock, config);
  LateCounter late(config.period_ns);
  executive.AddObserver(late);
  NoopTask task;
  executive.Run(task);
  const auto s = executive.stats().wake_latency.Summary();
  LatencyFigures f;
  f.samples = s.count;
  f.min_us = static_cast<double>(s.min_ns) / 1e3;
  f.avg_us = s.mean_ns / 1e3;
  f.p99_us = static_cast<double>(s.p99_ns) / 1e3;
  f.p999_us = static_cast<double>(s.p999_ns) / 1e3;
  f.max_us = static_cast<double>(s.max_ns) / 1e3;
  f.late = late.late;
  f.deadline_misses = late.misses;
  return f;
}

/// cyclictest's stdout (run by argv, no shell); exits with its stderr when it cannot run.
std::string CyclictestOutput(const std::vector<std::string>& argv) {
  hiltwin::kernel_glue::ProcessOptions streams;
  streams.out = hiltwin::kernel_glue::OutputTarget::Capture();
  streams.err = hiltwin::kernel_glue::OutputTarget::Capture();
  hiltwin::kernel_glue::ProcessResult run;
  try {
    run = hiltwin::kernel_glue::RunProcess(argv, streams);
  } catch (const hiltwin::kernel_glue::SpawnError& e) {
    std::fprintf(stderr, "%s%s\n", e.what(), e.NotFound() ? " (apt-get install rt-tests)" : "");
    std::exit(2);
  }
  if (!run.status.Success()) {
    std::fprintf(stderr, "cyclictest failed (%s): %s\n", run.status.Describe().c_str(),
                 run.err.c_str());
    std::exit(2);
  }
  return std::move(run.out);
}

/// Runs cyclictest with a 1 µs-bucket histogram up to 20 ms and derives the same figures.
LatencyFigures RunCyclictest(double rate_hz, double seconds, int priority) {
  const long interval_us = std::lround(1e6 / rate_hz);
  const long loops = std::lround(rate_hz * seconds);
  constexpr long kHistogramUs = 20'000;
  const std::vector<std::string> argv = {
      "cyclictest", "-m", "-q", "-p" + std::to_string(priority), "-i" + std::to_string(interval_us),
      "-l" + std::to_string(loops), "-h" + std::to_string(kHistogramUs)};
  std::vector<std::uint64_t> histogram(kHistogramUs, 0);
  std::uint64_t overflows = 0;
  LatencyFigures f;
  std::istringstream lines(CyclictestOutput(argv));
  for (std::string line; std::getline(lines, line);) {
    long bucket = 0;
    unsigned long long count = 0;
    if (line[0] != '#' && std::sscanf(line.c_str(), "%ld %llu", &bucket, &count) == 2) {
      if (bucket >= 0 && bucket < kHistogramUs) histogram[static_cast<std::size_t>(bucket)] = count;
    } else if (std::sscanf(line.c_str(), "# Min Latencies: %lf", &f.min_us) == 1) {
    } else if (std::sscanf(line.c_str(), "# Avg Latencies: %lf", &f.avg_us) == 1) {
    } else if (std::sscanf(line.c_str(), "# Max Latencies: %lf", &f.max_us) == 1) {
    } else if (std::sscanf(line.c_str(), "# Histogram Overflows: %llu", &count) == 1) {
      overflows = count;
    }
  }
  std::uint64_t total = overflows;
  for (auto c : histogram) total += c;
  f.samples = total;
  auto quantile = [&](double q) {
    const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total)));
    std::uint64_t seen = 0;
    for (std::size_t us = 0; us < histogram.size(); ++us) {
      seen += histogram[us];
      // Bucket `us` holds [us, us+1) µs: report its midpoint, as the executive's log-linear
      // histogram does, so neither side gains from rounding.
      if (seen >= rank) return static_cast<double>(us) + 0.5;
    }
    return f.max_us;  // in the overflow region: the max is the best bound we have
  };
  f.p99_us = quantile(0.99);
  f.p999_us = quantile(0.999);
  for (long us = interval_us + 1; us < kHistogramUs; ++us) f.late += histogram[static_cast<std::size_t>(us)];
  f.late += overflows;
  return f;
}

void Print(const char* who, const LatencyFigures& f) {
  std::printf("  %-11s min %7.1f  avg %7.1f  p99 %8.1f  p99.9 %8.1f  max %9.1f us  late %6llu/%llu (%.3f %%)\n",
              who, f.min_us, f.avg_us, f.p99_us, f.p999_us, f.max_us,
              static_cast<unsigned long long>(f.late), static_cast<unsigned long long>(f.samples),
              f.samples ? 100.0 * static_cast<double>(f.late) / static_cast<double>(f.samples) : 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> rates{1000, 4000, 10000, 20000};
  double seconds = 10.0;
  int priority = 90;
  int rounds = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--seconds") == 0) seconds = std::atof(argv[i + 1]);
    else if (std::strcmp(argv[i], "--priority") == 0) priority = std::atoi(argv[i + 1]);
    else if (std::strcmp(argv[i], "--rounds") == 0) rounds = std::max(1, std::atoi(argv[i + 1]));
    else if (std::strcmp(argv[i], "--rates") == 0) {
      rates.clear();
      for (char* tok = std::strtok(argv[i + 1], ","); tok; tok = std::strtok(nullptr, ",")) rates.push_back(std::atof(tok));
    } else {
      std::fprintf(stderr, "usage: %s [--rates 1000,4000] [--seconds S] [--priority P] [--rounds N]\n", argv[0]);
      return 2;
    }
  }
  hiltwin::kernel_glue::RtSetupRequest request;
  request.fifo_priority = priority;
  const auto session = hiltwin::kernel_glue::RtSession::Apply(request);
  std::printf("hiltwin executive vs cyclictest, %.0f s each, alternating; RT: %s\n", seconds,
              hiltwin::kernel_glue::Summary(session.record()).c_str());
  for (double rate_hz : rates) {
    std::printf("%.0f Hz (period %.1f us)\n", rate_hz, 1e6 / rate_hz);
    std::vector<double> p99_ratios;
    for (int round = 1; round <= rounds; ++round) {
      const LatencyFigures ours = RunHiltwin(rate_hz, seconds);
      const LatencyFigures peer = RunCyclictest(rate_hz, seconds, priority);
      std::printf(" round %d\n", round);
      Print("hiltwin", ours);
      Print("cyclictest", peer);
      p99_ratios.push_back(ours.p99_us / std::max(peer.p99_us, 1.0));
      std::printf("  ratio hiltwin/cyclictest: avg %.2f  p99 %.2f  p99.9 %.2f  late %s  (executive deadline misses: %llu)\n",
                  ours.avg_us / peer.avg_us, p99_ratios.back(),
                  ours.p999_us / std::max(peer.p999_us, 1.0),
                  peer.late ? std::to_string(static_cast<double>(ours.late) / static_cast<double>(peer.late)).c_str() : "n/a",
                  static_cast<unsigned long long>(ours.deadline_misses));
    }
    std::sort(p99_ratios.begin(), p99_ratios.end());
    const std::size_t n = p99_ratios.size();
    const double median = n % 2 == 1 ? p99_ratios[n / 2] : 0.5 * (p99_ratios[n / 2 - 1] + p99_ratios[n / 2]);
    std::printf("  %.0f Hz: median p99 ratio over %zu rounds %.2f (target <= 1.10)\n", rate_hz, n, median);
  }
  return 0;
}
