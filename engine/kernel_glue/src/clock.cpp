#include "hiltwin/kernel_glue/clock.h"

#include <cerrno>
#include <ctime>

namespace hiltwin::kernel_glue {
namespace {

timespec ToTimespec(TimeNs t_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(t_ns % kNsPerS);
  return ts;
}

}  // namespace

TimeNs MonotonicClock::NowNs() const noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerS + static_cast<TimeNs>(ts.tv_nsec);
}

void MonotonicClock::SleepUntilNs(TimeNs deadline_ns) noexcept {
  const timespec ts = ToTimespec(deadline_ns);
  // Absolute sleep: an interrupted call is simply repeated with the same deadline.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void MonotonicClock::SpendNs(TimeNs duration_ns) noexcept {
  const TimeNs until_ns = NowNs() + duration_ns;
  while (NowNs() < until_ns) {
  }
}

}  // namespace hiltwin::kernel_glue
