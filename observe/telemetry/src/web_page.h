#pragma once
// The live page (observe/telemetry/web/index.html), embedded at build time so the binary serves it
// with no file beside it.

#include <string_view>

namespace hiltwin::telemetry::web {

/// The whole page: HTML with its CSS and JavaScript inline, no external reference.
[[nodiscard]] std::string_view PageHtml() noexcept;

}  // namespace hiltwin::telemetry::web
