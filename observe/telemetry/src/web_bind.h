#pragma once
// Why the web sink could not bind its port, in words a user can act on. httplib's
// bind_to_port only says "false", and "the port is taken" and "that address is not this
// machine's" need different fixes, so a probe socket repeats the bind and reports its errno.
// And, once bound, the address the socket really has: `--web 0:8080` or `localhost:8080` name
// it in a form the resolver understands and a reader may not.

#include <optional>
#include <string>

#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry::web {

/// The errno of binding and listening on the endpoint as httplib does (SO_REUSEADDR); 0 when
/// it succeeds now; -1 when the address does not resolve.
[[nodiscard]] int ProbeBind(const WebEndpoint& endpoint);

/// "--web ADDR:PORT: <what is wrong>; <what to do>" for a probe's result.
[[nodiscard]] std::string BindFailureMessage(const WebEndpoint& endpoint, int probe_error);

/// The numeric address and port the listening socket `fd` is bound to (getsockname), e.g.
/// 0.0.0.0 for "0", 127.0.0.1 for "127.1"; nullopt when the socket cannot say.
[[nodiscard]] std::optional<WebEndpoint> BoundEndpoint(int fd);

/// "http://ADDR:PORT/", an IPv6 address in brackets.
[[nodiscard]] std::string UrlOf(const WebEndpoint& endpoint);

/// Whether the address is the wildcard (0.0.0.0 or ::): every interface of this machine.
[[nodiscard]] bool IsEveryInterface(const std::string& address);

}  // namespace hiltwin::telemetry::web
