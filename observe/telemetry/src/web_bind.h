#pragma once
// Why the web sink could not bind its port, in words a user can act on. httplib's
// bind_to_port only says "false", and "the port is taken" and "that address is not this
// machine's" need different fixes, so a probe socket repeats the bind and reports its errno.

#include <string>

#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry::web {

/// The errno of binding and listening on the endpoint as httplib does (SO_REUSEADDR); 0 when
/// it succeeds now; -1 when the address does not resolve.
[[nodiscard]] int ProbeBind(const WebEndpoint& endpoint);

/// "--web ADDR:PORT: <what is wrong>; <what to do>" for a probe's result.
[[nodiscard]] std::string BindFailureMessage(const WebEndpoint& endpoint, int probe_error);

}  // namespace hiltwin::telemetry::web
