// The single translation unit that instantiates the `hiltwin` tracepoint provider (probe
// code and tracepoint definitions). Referencing any HILTWIN_TRACE pulls it out of the
// static library, and with it the constructor that registers the probes.
#if defined(HILTWIN_WITH_LTTNG)
#define LTTNG_UST_TRACEPOINT_CREATE_PROBES
#define LTTNG_UST_TRACEPOINT_DEFINE
#include "hiltwin/tracing/tp_hiltwin.h"
#endif
