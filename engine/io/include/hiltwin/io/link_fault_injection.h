#pragma once
/// Fault injection on the FPGA link: corrupted, dropped and delayed SPI frames and a stuck
/// encoder, armed on the emulated board (mock and wire backends) at chosen exchanges, so a
/// user can watch what the run does with a broken link (docs/reliability.md's fault matrix).
/// The board's own hooks (FaultInjection) do the damage; this only decides when.
///
/// SPEC forms (comma-separated, repeatable flag):
///   KIND,at=K[,count=N]   KIND: corrupt-request | corrupt-answer | drop-answer |
///                         delay-answer | stuck-encoder
/// Exchange K is the K-th frame exchange of the run (0-based; the exchange of cycle K when no
/// release was skipped). Frame faults hit exchanges K .. K+N-1 (count defaults to 1); a stuck
/// encoder emits (twin) or sees (ECS) nothing from exchange K on, for N exchanges when count
/// is given, else to the end of the run.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/io/emulated_fpga.h"

namespace hiltwin::io {

struct LinkFaultInjection {
  enum class Kind : std::uint8_t {
    kCorruptRequest,
    kCorruptAnswer,
    kDropAnswer,
    kDelayAnswer,
    kStuckEncoder,
  };
  Kind kind = Kind::kCorruptAnswer;
  std::uint64_t first_exchange = 0;  ///< at=
  std::uint64_t count = 1;           ///< count=; stuck-encoder without count: to the end
  bool until_end = false;            ///< stuck-encoder given no count
};

/// Parses one SPEC; throws std::invalid_argument quoting it, saying what is wrong and the
/// accepted forms (the caller names the flag).
[[nodiscard]] LinkFaultInjection ParseLinkFaultInjection(std::string_view spec);
/// The SPEC form, e.g. "drop-answer,at=4000,count=3".
[[nodiscard]] std::string Describe(const LinkFaultInjection& injection);

/// A fixed set of link faults, applied to a board exchange by exchange without allocating.
class LinkFaultSchedule {
 public:
  static constexpr std::size_t kMaxInjections = 8;
  /// Throws std::length_error past kMaxInjections.
  void Add(const LinkFaultInjection& injection);
  /// Throws std::invalid_argument naming the first injection whose exchange K is not below
  /// `planned_exchanges` (0: the run has no end, every exchange may come).
  void CheckFiresWithin(std::uint64_t planned_exchanges) const;
  /// Arms `faults` for exchange `exchange`: frame faults at their first exchange (the board
  /// consumes one per frame), the stuck encoder on and off at its edges. Real-time path.
  void Arm(std::uint64_t exchange, FaultInjection& faults) const noexcept;
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] std::span<const LinkFaultInjection> injections() const noexcept {
    return {injections_.data(), size_};
  }

 private:
  std::array<LinkFaultInjection, kMaxInjections> injections_{};
  std::size_t size_ = 0;
};

}  // namespace hiltwin::io
