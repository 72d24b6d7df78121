// Emits hiltwin events a correct run never does, for the CTF reader's refusals: `<exe> CASE`.
// Every case starts with loop_start {period_ns = 1000, deadline_ns = 1000, planned_cycles = 3,
// rules = 0} and cycles k = 0, 1 (cycle k: release_ns = 1000k, wake +10, start +20, end +30);
// then, as event 4 onwards of the trace (events numbered from 1):
//   io_error_kind   io_error {k = 1, kind = 7}
//   rule_kind       qos_rule {rule = 0, kind = 9, m = 1, k = 2, n = 0, ppm = 0}
//   state_code      state_transition {k = 1, from = 2, to = 42, event = 1}
//   k_order         cycle k = 0 again
//   two_runs        loop_end, then a second loop_start and cycles 0..4 (as `hiltwin tune`
//                   runs several candidates in one process)
#include <unistd.h>

#include <cstdint>
#include <cstring>

#include "hiltwin/tracing/trace.h"

namespace {

void LoopStart() {
  HILTWIN_TRACE(loop_start, static_cast<std::int32_t>(::gettid()), 0, 0, 0, std::int64_t{1000},
                std::int64_t{1000}, std::uint64_t{3}, std::uint32_t{0});
}

void Cycle(std::uint64_t k) {
  const auto base_ns = static_cast<std::int64_t>(1000 * k);
  HILTWIN_TRACE(cycle, k, base_ns, base_ns + 10, base_ns + 20, base_ns + 30, std::int64_t{0},
                std::uint32_t{0}, std::uint8_t{0}, std::uint8_t{1});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const auto is = [argv](const char* name) { return std::strcmp(argv[1], name) == 0; };
  LoopStart();
  Cycle(0);
  Cycle(1);
  if (is("io_error_kind")) {
    HILTWIN_TRACE(io_error, std::uint64_t{1}, std::uint8_t{7});
  } else if (is("rule_kind")) {
    HILTWIN_TRACE(qos_rule, std::uint32_t{0}, std::uint8_t{9}, std::uint32_t{1}, std::uint32_t{2},
                  std::uint32_t{0}, std::uint32_t{0});
  } else if (is("state_code")) {
    HILTWIN_TRACE(state_transition, std::uint64_t{1}, std::uint8_t{2}, std::uint8_t{42},
                  std::uint8_t{1});
  } else if (is("k_order")) {
    Cycle(0);
  } else if (is("two_runs")) {
    HILTWIN_TRACE(loop_end, std::uint64_t{2}, std::uint64_t{2});
    LoopStart();
    for (std::uint64_t k = 0; k < 5; ++k) Cycle(k);
  } else {
    return 2;
  }
  return 0;
}
