// Emits a known sequence of every hiltwin tracepoint, for the live-session tests and the CTF
// reader's known-answer tests: `<exe> COUNT [GO_FILE]`. With GO_FILE it waits until that file
// exists before the first event: a process already running when the session daemon starts.
//   loop_start {tid = gettid, cpu = 0, policy = 1, priority = 80, period_ns = 1000,
//               deadline_ns = 1000, planned_cycles = COUNT, rules = 1}
//   qos_rule   {rule = 0, kind = 0 (mk_firm), m = 3, k = 4, n = 0, max_miss_ppm = 0}
//   cycle k:   release_ns = 1000k, wake = +10, start = +20, end = +30 + k%7, io_ns = 5,
//              skipped = k%3==0, missed = k%10==0, judged = 1
//   deadline_miss {k, lateness_ns = k%7 + 30 - 1000} after each missed cycle
//   qos_violation {rule = 0, k, distance = 0, violations = k/10 + 1} after each missed cycle
//   io_error {k, kind = (k/50)%4} for k%50 == 0
//   state_transition {k = 0, from = 2 (run), to = 3 (paused), event = 1 (start)} before the
//              cycles: codes only, not a legal transition (readers decode, not judge)
//   loop_end {cycles_run = COUNT, releases = COUNT}
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "hiltwin/tracing/trace.h"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) return 2;
  const auto count = static_cast<std::uint64_t>(std::strtoull(argv[1], nullptr, 10));
  while (argc == 3 && !std::filesystem::exists(argv[2])) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  HILTWIN_TRACE(loop_start, static_cast<std::int32_t>(::gettid()), 0, 1, 80, std::int64_t{1000},
                std::int64_t{1000}, count, std::uint32_t{1});
  HILTWIN_TRACE(qos_rule, std::uint32_t{0}, std::uint8_t{0}, std::uint32_t{3}, std::uint32_t{4},
                std::uint32_t{0}, std::uint32_t{0});
  HILTWIN_TRACE(state_transition, std::uint64_t{0}, std::uint8_t{2}, std::uint8_t{3},
                std::uint8_t{1});
  for (std::uint64_t k = 0; k < count; ++k) {
    const auto base_ns = static_cast<std::int64_t>(1000 * k);
    const auto end_offset_ns = 30 + static_cast<std::int64_t>(k % 7);
    const bool missed = k % 10 == 0;
    HILTWIN_TRACE(cycle, k, base_ns, base_ns + 10, base_ns + 20, base_ns + end_offset_ns,
                  std::int64_t{5}, static_cast<std::uint32_t>(k % 3 == 0 ? 1 : 0),
                  static_cast<std::uint8_t>(missed ? 1 : 0), std::uint8_t{1});
    if (missed) {
      HILTWIN_TRACE(deadline_miss, k, end_offset_ns - 1000);
      HILTWIN_TRACE(qos_violation, std::uint32_t{0}, k, std::uint32_t{0}, k / 10 + 1);
    }
    if (k % 50 == 0) HILTWIN_TRACE(io_error, k, static_cast<std::uint8_t>((k / 50) % 4));
  }
  HILTWIN_TRACE(loop_end, count, count);
  return 0;
}
