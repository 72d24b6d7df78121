#pragma once
// The text `hiltwin --version` prints: "hiltwin <project version> (git <describe>)". Generated at
// build time (cmake/WriteVersionSource.cmake), so it names the commit the binary was built from.

namespace hiltwin::app {
extern const char* const kVersionText;
}  // namespace hiltwin::app
