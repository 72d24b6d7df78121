#pragma once
/// Nanoseconds as the microseconds every output prints, one
/// definition for the text, HTML, Perfetto and tune reports.

#include <cstdint>

namespace hiltwin::analysis::detail {

[[nodiscard]] constexpr double Us(std::int64_t ns) noexcept { return static_cast<double>(ns) / 1e3; }
[[nodiscard]] constexpr double Us(double ns) noexcept { return ns / 1e3; }

}  // namespace hiltwin::analysis::detail
