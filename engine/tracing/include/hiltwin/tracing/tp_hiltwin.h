/// LTTng-UST tracepoint provider `hiltwin`: every event of the project, in one place.
/// Do not include directly; use hiltwin/tracing/trace.h and HILTWIN_TRACE. The events are
/// instantiated once, in tracing/src/tp_hiltwin.cpp. Every field is an integer (no strings in
/// the loop); the codes are the enums of trace_codes.h. Times are on CLOCK_MONOTONIC, as the
/// executive measures them, in nanoseconds.
///
/// Once per run, from the loop thread before its first cycle:
///   hiltwin:loop_start     {tid, cpu, policy, priority, period_ns, deadline_ns, planned_cycles,
///                           rules}
///   hiltwin:qos_rule       {rule, kind, m, k, n, max_miss_ppm}     one per configured rule
/// Every cycle:
///   hiltwin:cycle          {k, release_ns, wake_ns, start_ns, end_ns, io_ns, skipped, missed,
///                           judged}   judged: 1 when the cycle counts in the QoS ledger
/// When it happens:
///   hiltwin:deadline_miss  {k, lateness_ns}          end - (release + deadline)
///   hiltwin:overrun_injected {k, extra_ns}           --inject-overrun busy time
///   hiltwin:qos_violation  {rule, k, distance, violations}
///                          a rule's violation count rose at release k; distance: the rule's
///                          distance to failure after it (0); violations: the new count
///   hiltwin:state_transition {k, from, to, event}    lifecycle codes (lifecycle enums)
///   hiltwin:io_error       {k, kind}                 IoErrorKind
/// Once per run, from the loop thread after its last cycle:
///   hiltwin:loop_end       {cycles_run, releases}

#undef LTTNG_UST_TRACEPOINT_PROVIDER
#define LTTNG_UST_TRACEPOINT_PROVIDER hiltwin

#undef LTTNG_UST_TRACEPOINT_INCLUDE
#define LTTNG_UST_TRACEPOINT_INCLUDE "hiltwin/tracing/tp_hiltwin.h"

#if !defined(HILTWIN_TRACING_TP_HILTWIN_H) || defined(LTTNG_UST_TRACEPOINT_HEADER_MULTI_READ)
#define HILTWIN_TRACING_TP_HILTWIN_H

#include <lttng/tracepoint.h>
#include <stdint.h>

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, loop_start,
    LTTNG_UST_TP_ARGS(int32_t, tid, int32_t, cpu, int32_t, policy, int32_t, priority, int64_t,
                      period_ns, int64_t, deadline_ns, uint64_t, planned_cycles, uint32_t, rules),
    LTTNG_UST_TP_FIELDS(
        lttng_ust_field_integer(int32_t, tid, tid) lttng_ust_field_integer(int32_t, cpu, cpu)
            lttng_ust_field_integer(int32_t, policy, policy)
                lttng_ust_field_integer(int32_t, priority, priority)
                    lttng_ust_field_integer(int64_t, period_ns, period_ns)
                        lttng_ust_field_integer(int64_t, deadline_ns, deadline_ns)
                            lttng_ust_field_integer(uint64_t, planned_cycles, planned_cycles)
                                lttng_ust_field_integer(uint32_t, rules, rules)))

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, qos_rule,
    LTTNG_UST_TP_ARGS(uint32_t, rule, uint8_t, kind, uint32_t, m, uint32_t, k, uint32_t, n,
                      uint32_t, max_miss_ppm),
    LTTNG_UST_TP_FIELDS(
        lttng_ust_field_integer(uint32_t, rule, rule) lttng_ust_field_integer(uint8_t, kind, kind)
            lttng_ust_field_integer(uint32_t, m, m) lttng_ust_field_integer(uint32_t, k, k)
                lttng_ust_field_integer(uint32_t, n, n)
                    lttng_ust_field_integer(uint32_t, max_miss_ppm, max_miss_ppm)))

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, cycle,
    LTTNG_UST_TP_ARGS(uint64_t, k, int64_t, release_ns, int64_t, wake_ns, int64_t, start_ns,
                      int64_t, end_ns, int64_t, io_ns, uint32_t, skipped, uint8_t, missed,
                      uint8_t, judged),
    LTTNG_UST_TP_FIELDS(
        lttng_ust_field_integer(uint64_t, k, k)
            lttng_ust_field_integer(int64_t, release_ns, release_ns)
                lttng_ust_field_integer(int64_t, wake_ns, wake_ns)
                    lttng_ust_field_integer(int64_t, start_ns, start_ns)
                        lttng_ust_field_integer(int64_t, end_ns, end_ns)
                            lttng_ust_field_integer(int64_t, io_ns, io_ns)
                                lttng_ust_field_integer(uint32_t, skipped, skipped)
                                    lttng_ust_field_integer(uint8_t, missed, missed)
                                        lttng_ust_field_integer(uint8_t, judged, judged)))

LTTNG_UST_TRACEPOINT_EVENT(hiltwin, deadline_miss, LTTNG_UST_TP_ARGS(uint64_t, k, int64_t, lateness_ns),
                           LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                                                   lttng_ust_field_integer(int64_t, lateness_ns,
                                                                           lateness_ns)))

LTTNG_UST_TRACEPOINT_EVENT(hiltwin, overrun_injected, LTTNG_UST_TP_ARGS(uint64_t, k, int64_t, extra_ns),
                           LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                                                   lttng_ust_field_integer(int64_t, extra_ns,
                                                                           extra_ns)))

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, qos_violation,
    LTTNG_UST_TP_ARGS(uint32_t, rule, uint64_t, k, uint32_t, distance, uint64_t, violations),
    LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint32_t, rule, rule)
                            lttng_ust_field_integer(uint64_t, k, k)
                                lttng_ust_field_integer(uint32_t, distance, distance)
                                    lttng_ust_field_integer(uint64_t, violations, violations)))

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, state_transition,
    LTTNG_UST_TP_ARGS(uint64_t, k, uint8_t, from, uint8_t, to, uint8_t, event),
    LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                            lttng_ust_field_integer(uint8_t, from, from)
                                lttng_ust_field_integer(uint8_t, to, to)
                                    lttng_ust_field_integer(uint8_t, event, event)))

LTTNG_UST_TRACEPOINT_EVENT(hiltwin, io_error, LTTNG_UST_TP_ARGS(uint64_t, k, uint8_t, kind),
                           LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                                                   lttng_ust_field_integer(uint8_t, kind, kind)))

LTTNG_UST_TRACEPOINT_EVENT(hiltwin, loop_end, LTTNG_UST_TP_ARGS(uint64_t, cycles_run, uint64_t, releases),
                           LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, cycles_run,
                                                                       cycles_run)
                                                   lttng_ust_field_integer(uint64_t, releases,
                                                                           releases)))

#endif  // HILTWIN_TRACING_TP_HILTWIN_H

#include <lttng/tracepoint-event.h>
