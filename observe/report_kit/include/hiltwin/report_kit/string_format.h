#pragma once
/// printf into a std::string of any length, for every text
/// output of the observe modules (assessment, jitter report, tune report).

#include <string>

namespace hiltwin::analysis::detail {

[[nodiscard]] std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace hiltwin::analysis::detail
