#pragma once
/// Fault injection for `hiltwin run --inject-overrun SPEC`: extra compute time added to
/// chosen cycles, on either clock (spun on the real clock, advanced on the virtual one), so
/// users can watch the QoS monitor react to a known miss pattern.
///
/// SPEC forms (comma-separated key=value, repeatable flag):
///   at=K[,count=N],extra-us=US     cycles K .. K+N-1 (count defaults to 1)
///   every=P[,offset=O],extra-us=US cycles k with k % P == O (offset defaults to 0)

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::app {

struct OverrunInjection {
  enum class Kind { kAt, kEvery } kind = Kind::kAt;
  std::uint64_t first_cycle = 0;  ///< at=
  std::uint64_t count = 1;        ///< count=
  std::uint64_t every = 0;        ///< every=
  std::uint64_t offset = 0;       ///< offset=
  kernel_glue::TimeNs extra_ns = 0;
};

/// Parses one SPEC; throws std::invalid_argument saying what is wrong and the accepted forms.
[[nodiscard]] OverrunInjection ParseOverrunInjection(std::string_view spec);

/// A fixed set of injections consulted once per cycle without allocating.
class OverrunInjector {
 public:
  static constexpr std::size_t kMaxInjections = 8;
  /// Throws std::length_error past kMaxInjections.
  void Add(const OverrunInjection& injection);
  /// Extra compute time for cycle k (sum of all matching injections).
  [[nodiscard]] kernel_glue::TimeNs ExtraNs(std::uint64_t cycle) const noexcept;
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }

 private:
  std::array<OverrunInjection, kMaxInjections> injections_{};
  std::size_t size_ = 0;
};

}  // namespace hiltwin::app
