#pragma once
// The live page (observe/telemetry/web/index.html) and the three.js its 3D view draws with,
// embedded at build time so the binary serves them with no file beside it.

#include <string_view>

namespace hiltwin::telemetry::web {

/// The whole page: HTML with its CSS and JavaScript inline; its one script beside it is
/// three.js, served by the same binary (ThreeJs).
[[nodiscard]] std::string_view PageHtml() noexcept;

/// three.min.js from libjs-three (observe/telemetry/CMakeLists.txt); empty in a build with
/// -DHILTWIN_WEB_3D=OFF, whose page shows its 2D view only.
[[nodiscard]] std::string_view ThreeJs() noexcept;

}  // namespace hiltwin::telemetry::web
