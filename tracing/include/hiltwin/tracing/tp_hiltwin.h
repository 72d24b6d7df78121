/// LTTng-UST tracepoint provider `hiltwin`: every event of the project, in one place.
/// Do not include directly; use hiltwin/tracing/trace.h and HILTWIN_TRACE. The events are
/// instantiated once, in tracing/src/tp_hiltwin.cpp.
///
/// Events (field units in the names; times on CLOCK_MONOTONIC, as the executive measures):
///   hiltwin:cycle  {k, release_ns, wake_ns, start_ns, end_ns, skipped, missed}
///   hiltwin:qos    {k, distance_to_failure, verdict}   verdict: 0 PASS, 1 FLAGGED, 2 ABORTED
///   hiltwin:mark   {k, code}                           free-form marker (fault injection,
///                                                      state changes)

#undef LTTNG_UST_TRACEPOINT_PROVIDER
#define LTTNG_UST_TRACEPOINT_PROVIDER hiltwin

#undef LTTNG_UST_TRACEPOINT_INCLUDE
#define LTTNG_UST_TRACEPOINT_INCLUDE "hiltwin/tracing/tp_hiltwin.h"

#if !defined(HILTWIN_TRACING_TP_HILTWIN_H) || defined(LTTNG_UST_TRACEPOINT_HEADER_MULTI_READ)
#define HILTWIN_TRACING_TP_HILTWIN_H

#include <lttng/tracepoint.h>
#include <stdint.h>

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, cycle,
    LTTNG_UST_TP_ARGS(uint64_t, k, int64_t, release_ns, int64_t, wake_ns, int64_t, start_ns,
                      int64_t, end_ns, uint32_t, skipped, uint8_t, missed),
    LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                            lttng_ust_field_integer(int64_t, release_ns, release_ns)
                                lttng_ust_field_integer(int64_t, wake_ns, wake_ns)
                                    lttng_ust_field_integer(int64_t, start_ns, start_ns)
                                        lttng_ust_field_integer(int64_t, end_ns, end_ns)
                                            lttng_ust_field_integer(uint32_t, skipped, skipped)
                                                lttng_ust_field_integer(uint8_t, missed, missed)))

LTTNG_UST_TRACEPOINT_EVENT(
    hiltwin, qos, LTTNG_UST_TP_ARGS(uint64_t, k, int64_t, distance_to_failure, uint8_t, verdict),
    LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                            lttng_ust_field_integer(int64_t, distance_to_failure,
                                                    distance_to_failure)
                                lttng_ust_field_integer(uint8_t, verdict, verdict)))

LTTNG_UST_TRACEPOINT_EVENT(hiltwin, mark, LTTNG_UST_TP_ARGS(uint64_t, k, int32_t, code),
                           LTTNG_UST_TP_FIELDS(lttng_ust_field_integer(uint64_t, k, k)
                                                   lttng_ust_field_integer(int32_t, code, code)))

#endif  // HILTWIN_TRACING_TP_HILTWIN_H

#include <lttng/tracepoint-event.h>
