// The LTTng channel's size for a loop rate. The figure that matters is how long the buffer
// rides out a consumer that falls behind (a disk flush, a busy CPU): events are discarded,
// never waited for (the loop must not block), so the buffer must be comfortably larger than
// what the consumer can leave unread.
#include <algorithm>
#include <bit>
#include <cmath>

#include "hiltwin/trace_capture/lttng_session.h"

namespace hiltwin::trace_capture {
namespace {

constexpr double kSubbufSeconds = 0.1;  // events one sub-buffer holds
constexpr std::uint64_t kMinSubbufBytes = std::uint64_t{256} * 1024;
constexpr std::uint64_t kSubbufCount = 8;
constexpr std::uint32_t kSwitchTimerUs = 100'000;

}  // namespace

// At 20 kHz: 20'000 cycles/s * 80 B = 1.6 MB/s; 0.1 s of it is 160'000 B, so sub-buffers of
// 256 KiB (the floor, and the next power of two), 8 of them: 2 MiB per CPU, 1.3 s of events.
// The 100 ms switch timer hands a sub-buffer to the consumer at least every 100 ms even when
// it is not full, so the consumer drains steadily (about one sub-buffer per 0.16 s at 20 kHz)
// instead of in bursts; it has more than a second of slack before anything is discarded, for
// as long as the run lasts (60 s at 20 kHz is 96 MB written, a steady 1.6 MB/s for the disk).
// At 100 kHz: 800'000 B per 0.1 s -> 1 MiB sub-buffers, 8 MiB per CPU, still 1.3 s.
LttngChannelSize ChannelSizeFor(double rate_hz) {
  const double rate = std::isfinite(rate_hz) ? std::max(rate_hz, 0.0) : 0.0;
  const double bytes = std::ceil(rate * static_cast<double>(kCycleEventBytes) * kSubbufSeconds);
  // Beyond 2^40 B the figure means nothing; the clamp only keeps the conversion defined.
  const auto wanted = static_cast<std::uint64_t>(std::min(bytes, 1099511627776.0));
  return LttngChannelSize{
      .subbuf_bytes = std::bit_ceil(std::max(wanted, kMinSubbufBytes)),
      .subbuf_count = kSubbufCount,
      .switch_timer_us = kSwitchTimerUs,
  };
}

}  // namespace hiltwin::trace_capture
