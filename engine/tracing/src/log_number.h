#pragma once
// The text of one log cell (CsvLogger's writer formats every cell of every row, so this is
// the writer's cost per row; docs/logs.md gives the format). Private to the module; the tests
// hold it to the formatter it replaced, cell for cell.

#include <cstddef>

namespace hiltwin::tracing::detail {

/// The most characters one cell takes: "-2.2250738585072014e-308".
inline constexpr std::size_t kMaxNumberChars = 24;
/// Bytes past a text's end that writing it may overwrite (digits are stored eight at a time):
/// the destination needs room for kMaxNumberChars + kNumberScratchChars.
inline constexpr std::size_t kNumberScratchChars = 8;

/// Writes `value` at `first` (room for kMaxNumberChars + kNumberScratchChars) and returns the
/// end of its text. NaN, Inf and -Inf
/// as MATLAB spells them; values with at most 6 decimals, multiples of 2^-11 (PWM duties) and
/// whole numbers below 2^53 as their exact decimal expansion; any other value as
/// FormatShortest. Every text reads back as the same double.
char* FormatLogNumber(char* first, double value) noexcept;

/// The text std::to_chars(first, last, value) writes for a finite double (same room) (the shortest that
/// reads back as the same double, fixed or scientific, whichever is shorter, fixed on a tie),
/// with the digits from Dragonbox, which costs about a third of the standard library's Ryu.
char* FormatShortest(char* first, double value) noexcept;

}  // namespace hiltwin::tracing::detail
