// A competitor with a known answer for `hiltwin trace --kernel`: a SCHED_FIFO thread named
// NAME at PRIORITY on CPU that busy-spins SPIN_MS then sleeps SLEEP_MS until TOTAL_S are over.
// `<exe> NAME CPU PRIORITY SPIN_MS SLEEP_MS TOTAL_S`. Prints "ready" once it runs at its
// priority on its CPU (exit 3 when the OS refuses either: the test then skips).
#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <time.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

long long NowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<long long>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s NAME CPU PRIORITY SPIN_MS SLEEP_MS TOTAL_S\n", argv[0]);
    return 2;
  }
  const std::string name = argv[1];
  const int cpu = std::atoi(argv[2]);
  const int priority = std::atoi(argv[3]);
  const long long spin_ns = std::atoll(argv[4]) * 1'000'000LL;
  const long long sleep_ns = std::atoll(argv[5]) * 1'000'000LL;
  const long long total_ns = std::atoll(argv[6]) * 1'000'000'000LL;
  prctl(PR_SET_NAME, name.c_str(), 0, 0, 0);
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  sched_param param{};
  param.sched_priority = priority;
  if (sched_setaffinity(0, sizeof set, &set) != 0 ||
      sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
    std::perror("hog: SCHED_FIFO on the chosen CPU refused");
    return 3;
  }
  std::puts("ready");
  std::fflush(stdout);
  const long long end_ns = NowNs() + total_ns;
  while (NowNs() < end_ns) {
    const long long spin_end_ns = NowNs() + spin_ns;
    while (NowNs() < spin_end_ns) {
    }
    const timespec pause{static_cast<time_t>(sleep_ns / 1'000'000'000LL),
                         static_cast<long>(sleep_ns % 1'000'000'000LL)};
    nanosleep(&pause, nullptr);
  }
  return 0;
}
