#pragma once
/// The timing log (`hiltwin run --timing-log FILE`): every cycle's time stamps, written by the
/// RT-safe CsvLogger, read back by `hiltwin trace --analyze FILE` (observe/traces:
/// timing_log_reader.cpp). It is the LTTng trace's `cycle` events for users who may not trace. The
/// format, in full:
///
///   # hiltwin timing log 1
///   # period_ns=50000
///   # deadline_ns=50000
///   # planned_cycles=200000
///   # rule=<qos::ToString(kind)> m=<m> k=<k> n=<n> max_miss_ppm=<ppm>     (one line per rule)
///   time_s,k,release_ns,wake_ns,start_ns,end_ns,io_ns,skipped,missed,judged
///   0,0,0,8123,8456,10234,812,0,0,1
///   ...
///
/// One row per executed cycle, in order. Times are integers in nanoseconds since release 0
/// (exact as doubles for 104 days); time_s is release_ns in seconds. The fields are those of
/// the hiltwin:cycle tracepoint. A run that stopped cleanly has every row; a torn last row means
/// the file was cut (the reader says so with the line number).

#include <array>
#include <string_view>

namespace hiltwin::tracing {

/// First preamble line, without the "# " the logger writes before every preamble line.
inline constexpr std::string_view kTimingLogMagic = "hiltwin timing log 1";

/// Value columns after time_s, in order.
inline constexpr std::array<const char*, 9> kTimingLogFields = {
    "k", "release_ns", "wake_ns", "start_ns", "end_ns", "io_ns", "skipped", "missed", "judged"};

}  // namespace hiltwin::tracing
