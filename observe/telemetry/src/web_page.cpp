#include "web_page.h"

#include "web_page_html.h"  // generated from telemetry/web/index.html (telemetry/CMakeLists.txt)

namespace hiltwin::telemetry::web {

std::string_view PageHtml() noexcept { return kPageHtml; }

}  // namespace hiltwin::telemetry::web
