#pragma once
// The text of one log cell (CsvLogger's writer formats every cell of every row, so this is
// the writer's cost per row; docs/logs.md gives the format). Private to the module; the tests
// hold it to the formatter it replaced, cell for cell.

#include <cstddef>
#include <cstdint>

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

/// The text std::to_chars(first, last, value) writes for a finite double (same room) (the
/// shortest that reads back as the same double, fixed or scientific, whichever is shorter,
/// fixed on a tie). For 2^-36 <= |value| < 2^49 the digits come from one 128-bit product,
/// about a quarter of the standard library's Ryu; other values go to std::to_chars.
char* FormatShortest(char* first, double value) noexcept;

/// One column's last cell: the bits of its value and the text FormatLogNumber gave them. A
/// column whose value keeps its bits from row to row (a held PWM duty, an encoder count that did
/// not move, a signal not in use) gets its text copied instead of formatted again. Exact: a
/// cell's text is a function of the value's bits alone. Starts as 0's text.
struct CellMemo {
  std::uint64_t bits = 0;                                ///< +0.0
  std::size_t length = 1;                                ///< of text
  char text[kMaxNumberChars + kNumberScratchChars] = {'0'};  ///< the cell, then scratch
};

/// Writes a row: `count` cells (count >= 1) separated by commas and a newline, at `first`
/// (room for count * (kMaxNumberChars + 1) + kNumberScratchChars), and returns its end.
/// `memos` holds one CellMemo per column, carried from row to row by the caller.
char* FormatLogRow(char* first, const double* values, std::size_t count,
                   CellMemo* memos) noexcept;

}  // namespace hiltwin::tracing::detail
