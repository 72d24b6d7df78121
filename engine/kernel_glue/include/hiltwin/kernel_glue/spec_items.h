#pragma once
// The comma-separated key=value SPEC form shared by the fault-injection flags
// (--inject-overrun, --inject-link-fault): one splitter and one number reader, so every flag
// words its errors the same way.

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>

namespace hiltwin::kernel_glue::spec_items {

/// Calls `item(text)` for each comma-separated item of `spec`, in order (empty items included,
/// so "a,,b" is caught by the caller's checks rather than silently skipped).
template <typename Item>
void ForEachItem(std::string_view spec, Item&& item) {
  std::string_view rest = spec;
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    item(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
  }
}

/// A whole number ≥ 0 (false for anything else: empty, a sign, trailing text, overflow).
inline bool ParseWhole(std::string_view text, std::uint64_t& value) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size();
}

/// The whole number ≥ 0 in `text`, the value of `key`; else calls `fail(what)`, which throws.
template <typename Fail>
std::uint64_t WholeOf(std::string_view key, std::string_view text, Fail&& fail) {
  std::uint64_t value = 0;
  if (!ParseWhole(text, value)) {
    fail("'" + std::string(key) + "' needs a whole number ≥ 0, got '" + std::string(text) + "'");
  }
  return value;
}

}  // namespace hiltwin::kernel_glue::spec_items
