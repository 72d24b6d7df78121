#pragma once
/// The one tracing macro. `HILTWIN_TRACE(event, args...)` fires the LTTng-UST tracepoint
/// `hiltwin:event` (see tp_hiltwin.h for the events and their arguments). Built without
/// HILTWIN_WITH_LTTNG it compiles to nothing: no code, no symbols, arguments not evaluated
/// (they sit in an unevaluated sizeof, so they are still type-checked and count as used).
/// With LTTng compiled in but no session recording, it costs one predictable branch on a
/// flag and its arguments are not evaluated either.

namespace hiltwin::tracing {

#if defined(HILTWIN_WITH_LTTNG)
/// Whether the tracepoints are compiled into this build.
inline constexpr bool kTracingCompiledIn = true;
#else
/// Whether the tracepoints are compiled into this build.
inline constexpr bool kTracingCompiledIn = false;
#endif

namespace detail {
/// Declared only: named inside sizeof by the disabled HILTWIN_TRACE, never called.
template <typename... Args>
int SwallowTraceArgs(const Args&... args) noexcept;
}  // namespace detail

}  // namespace hiltwin::tracing

#if defined(HILTWIN_WITH_LTTNG)
#include "hiltwin/tracing/tp_hiltwin.h"
#define HILTWIN_TRACE(event, ...) lttng_ust_tracepoint(hiltwin, event, __VA_ARGS__)
#else
#define HILTWIN_TRACE(event, ...) \
  static_cast<void>(sizeof(::hiltwin::tracing::detail::SwallowTraceArgs(__VA_ARGS__)))
#endif
