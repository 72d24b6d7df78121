#pragma once
/// Fault injection: extra compute time added to chosen cycles of any task, on either clock
/// (spun on the real clock, advanced on the virtual one), so users can watch the QoS monitor
/// react to a known miss pattern. RunSession applies it after the task's step.
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

namespace hiltwin::runtime {

struct OverrunInjection {
  enum class Kind { kAt, kEvery } kind = Kind::kAt;
  std::uint64_t first_cycle = 0;  ///< at=
  std::uint64_t count = 1;        ///< count=
  std::uint64_t every = 0;        ///< every=
  std::uint64_t offset = 0;       ///< offset=
  kernel_glue::TimeNs extra_ns = 0;
};

/// Parses one SPEC; throws std::invalid_argument quoting the SPEC, saying what is wrong and
/// the accepted forms (the caller names where the SPEC came from).
[[nodiscard]] OverrunInjection ParseOverrunInjection(std::string_view spec);

/// The SPEC form of an injection, e.g. "at=40000,count=3,extra-us=600".
[[nodiscard]] std::string Describe(const OverrunInjection& injection);

/// A fixed set of injections consulted once per cycle without allocating.
class OverrunInjector {
 public:
  static constexpr std::size_t kMaxInjections = 8;
  /// Throws std::length_error past kMaxInjections.
  void Add(const OverrunInjection& injection);
  /// Throws std::invalid_argument naming the first injection that would never fire in a run
  /// of `planned_cycles` releases (cycles 0 .. planned_cycles - 1): silently ignoring it would
  /// let a user believe the QoS monitor coped with an overrun that never happened.
  void CheckFiresWithin(std::uint64_t planned_cycles) const;
  /// Extra compute time for cycle k (sum of all matching injections).
  [[nodiscard]] kernel_glue::TimeNs ExtraNs(std::uint64_t cycle) const noexcept;
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }

 private:
  std::array<OverrunInjection, kMaxInjections> injections_{};
  std::size_t size_ = 0;
};

}  // namespace hiltwin::runtime
