// Emits a known sequence of hiltwin tracepoints, for the live-session test: `<exe> COUNT`.
// cycle k: release_ns = 1000k, wake = +10, start = +20, end = +30 + k%7, skipped = k%3==0,
// missed = k%10==0; qos k: distance_to_failure = COUNT-k, verdict = k%3.
#include <cstdint>
#include <cstdlib>

#include "hiltwin/tracing/trace.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const auto count = static_cast<std::uint64_t>(std::strtoull(argv[1], nullptr, 10));
  for (std::uint64_t k = 0; k < count; ++k) {
    const auto base_ns = static_cast<std::int64_t>(1000 * k);
    HILTWIN_TRACE(cycle, k, base_ns, base_ns + 10, base_ns + 20,
                  base_ns + 30 + static_cast<std::int64_t>(k % 7),
                  static_cast<std::uint32_t>(k % 3 == 0 ? 1 : 0),
                  static_cast<std::uint8_t>(k % 10 == 0 ? 1 : 0));
    HILTWIN_TRACE(qos, k, static_cast<std::int64_t>(count - k), static_cast<std::uint8_t>(k % 3));
  }
  return 0;
}
