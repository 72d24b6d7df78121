// three.js for the page's 3D view, in a unit of its own: its 850 kB literal is compiled once,
// with the one warning it trips switched off (observe/telemetry/CMakeLists.txt).
#include "web_page.h"

#if HILTWIN_WEB_3D
#include "web_three_js.h"  // generated from libjs-three's three.min.js
#endif

namespace hiltwin::telemetry::web {

std::string_view ThreeJs() noexcept {
#if HILTWIN_WEB_3D
  return kThreeJs;
#else
  return {};
#endif
}

}  // namespace hiltwin::telemetry::web
