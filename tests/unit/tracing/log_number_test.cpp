// The log cell formatter (engine/tracing/src/log_number.h) against the one it replaced, kept
// here verbatim as the reference: the log must stay byte-identical. And its shortest form
// against std::to_chars, whose text the log format names.
#include "log_number.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

using hiltwin::tracing::detail::CellMemo;
using hiltwin::tracing::detail::FormatLogNumber;
using hiltwin::tracing::detail::FormatLogRow;
using hiltwin::tracing::detail::FormatShortest;
using hiltwin::tracing::detail::kMaxNumberChars;
using hiltwin::tracing::detail::kNumberScratchChars;

// ---- The reference: csv_logger.cpp's FormatFixed and FormatDouble before issue 36. ----
char* RefFormatFixed(char* first, char* last, bool negative, std::uint64_t units, int decimals) {
  if (negative) *first++ = '-';
  std::uint64_t scale = 1;
  for (int i = 0; i < decimals; ++i) scale *= 10U;
  first = std::to_chars(first, last, units / scale).ptr;
  std::uint64_t fraction = units % scale;
  if (fraction == 0) return first;
  while (fraction % 10U == 0) {
    fraction /= 10U;
    --decimals;
  }
  *first++ = '.';
  char* const end = first + decimals;
  for (char* p = end; p != first; fraction /= 10U) *--p = static_cast<char>('0' + fraction % 10U);
  return end;
}

char* RefFormatDouble(char* first, char* last, double value) {
  if (std::isnan(value)) return std::copy_n("NaN", 3, first);
  if (std::isinf(value)) {
    if (value < 0) *first++ = '-';
    return std::copy_n("Inf", 3, first);
  }
  const double magnitude = std::fabs(value);
  const bool negative = std::signbit(value);
  if (magnitude < 1e6) {
    const double micros = std::nearbyint(magnitude * 1e6);
    if (micros / 1e6 == magnitude) {
      return RefFormatFixed(first, last, negative, static_cast<std::uint64_t>(micros), 6);
    }
    const double steps = magnitude * 2048.0;
    if (steps == std::floor(steps)) {
      return RefFormatFixed(first, last, negative,
                            static_cast<std::uint64_t>(steps) * 48'828'125U, 11);
    }
  } else if (magnitude < 9007199254740992.0) {
    const auto whole = static_cast<std::int64_t>(value);
    if (static_cast<double>(whole) == value) return std::to_chars(first, last, whole).ptr;
  }
  return std::to_chars(first, last, value).ptr;
}
// ---- end of the reference ----

std::string Reference(double value) {
  char text[64];
  return {text, RefFormatDouble(text, text + sizeof text, value)};
}

// The text, after checking that it and the scratch written past it stay in their room.
std::string Cell(double value) {
  char text[kMaxNumberChars + kNumberScratchChars + 16];
  std::fill(std::begin(text), std::end(text), '#');
  char* const end = FormatLogNumber(text, value);
  EXPECT_LE(end - text, static_cast<std::ptrdiff_t>(kMaxNumberChars)) << Reference(value);
  EXPECT_TRUE(std::all_of(end + kNumberScratchChars, std::end(text), [](char c) {
    return c == '#';
  })) << Reference(value);
  return {text, end};
}

std::string StdShortest(double value) {
  char text[64];
  return {text, std::to_chars(text, text + sizeof text, value).ptr};
}

std::string Shortest(double value) {
  char text[kMaxNumberChars + kNumberScratchChars];
  return {text, FormatShortest(text, value)};
}

// Compares cell for cell; stops after a few mismatches so a broken build says what, briefly.
void ExpectSameCells(const std::vector<double>& values) {
  int mismatches = 0;
  for (const double v : values) {
    const std::string expected = Reference(v);
    const std::string actual = Cell(v);
    if (expected != actual) {
      ADD_FAILURE() << "value " << StdShortest(v) << " (bits 0x" << std::hex
                    << std::bit_cast<std::uint64_t>(v) << "): expected " << expected << ", got "
                    << actual;
      if (++mismatches == 10) return;
    }
  }
}

double FromBits(std::uint64_t bits) { return std::bit_cast<double>(bits); }

constexpr std::int64_t kPow10Test[] = {1,           10,           100,           1'000,
                                       10'000,      100'000,      1'000'000,     10'000'000,
                                       100'000'000, 1'000'000'000, 10'000'000'000, 100'000'000'000,
                                       1'000'000'000'000, 10'000'000'000'000,
                                       100'000'000'000'000, 1'000'000'000'000'000,
                                       10'000'000'000'000'000, 100'000'000'000'000'000};

TEST(LogNumberTest, SpecialValuesAreSpelledAsBefore) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(Cell(std::nan("")), "NaN");
  EXPECT_EQ(Cell(-std::nan("")), "NaN");
  EXPECT_EQ(Cell(inf), "Inf");
  EXPECT_EQ(Cell(-inf), "-Inf");
  EXPECT_EQ(Cell(0.0), "0");
  EXPECT_EQ(Cell(-0.0), "-0");
  EXPECT_EQ(Cell(0.25025000000000003), "0.25025000000000003");
  EXPECT_EQ(Cell(4.99975), "4.99975");
  EXPECT_EQ(Cell(0.7998046875), "0.7998046875");
  EXPECT_EQ(Cell(1e-06), "0.000001");  // the 6-decimal shortcut, not to_chars' 1e-06
  EXPECT_EQ(Cell(1e-07), "1e-07");
  EXPECT_EQ(Cell(123456789.0), "123456789");
  EXPECT_EQ(Cell(-1.7241130790320105), "-1.7241130790320105");
  ExpectSameCells({std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::min(), std::numeric_limits<double>::denorm_min(),
                   -std::numeric_limits<double>::denorm_min(), 9007199254740992.0,
                   9007199254740991.0, -9007199254740993.0, 1e6, 999999.9999995, 1e22, 1e23,
                   0.1, 0.2, 0.3, 1.0 / 3.0, 5e-324, 1.5e-5, 0.0001, 0.00001});
}

TEST(LogNumberTest, TwinShapedCellsMatchTheFormerFormatter) {
  std::vector<double> values;
  for (std::int64_t k = 0; k < 200'000; ++k) {
    values.push_back(static_cast<double>(k) * 0.00025);            // time stamps k * h
    values.push_back(static_cast<double>(k - 100'000) / 2048.0);   // PWM duties
    values.push_back(static_cast<double>(k * 7919 - 3'000'000));   // counters, encoder counts
    values.push_back(static_cast<double>(k) * 1e-6 - 0.1);         // microseconds, not exact
  }
  ExpectSameCells(values);
}

TEST(LogNumberTest, ValuesAtTheShortcutsEdgesMatchTheFormerFormatter) {
  std::vector<double> values;
  std::mt19937_64 random(36);
  std::uniform_int_distribution<std::int64_t> units(-999'999'999'999, 999'999'999'999);
  for (int i = 0; i < 100'000; ++i) {
    // n micro-units and their neighbours, and half-way points the rounding must treat alike.
    const double v = static_cast<double>(units(random)) / 1e6;
    values.push_back(v);
    values.push_back(std::nextafter(v, 0.0));
    values.push_back(std::nextafter(v, 2e6));
    values.push_back((static_cast<double>(units(random)) + 0.5) / 1e6);
    values.push_back(static_cast<double>(units(random) % 1'000'000'000) / 2048.0);
  }
  for (int e = -30; e <= 30; ++e) {
    const double p = std::pow(10.0, e);
    for (const double v : {p, std::nextafter(p, 0.0), std::nextafter(p, 1e300), 1e6 - p}) {
      values.push_back(v);
      values.push_back(-v);
    }
  }
  ExpectSameCells(values);
}

TEST(LogNumberTest, RandomDoublesMatchTheFormerFormatter) {
  std::vector<double> values;
  std::mt19937_64 random(3636);
  std::uniform_real_distribution<double> state(-10.0, 10.0);
  for (int i = 0; i < 200'000; ++i) {
    values.push_back(FromBits(random()));  // every exponent, NaN and Inf included
    values.push_back(state(random));       // a model's states: full precision
    values.push_back(state(random) * 1e-5);
  }
  ExpectSameCells(values);
}

TEST(LogNumberTest, ShortestIsTheStandardLibrarysText) {
  std::mt19937_64 random(360);
  int mismatches = 0;
  for (int i = 0; i < 300'000 && mismatches < 10; ++i) {
    const double v = FromBits(random());
    if (!std::isfinite(v)) continue;
    if (Shortest(v) != StdShortest(v)) {
      ++mismatches;
      ADD_FAILURE() << "bits 0x" << std::hex << std::bit_cast<std::uint64_t>(v) << ": expected "
                    << StdShortest(v) << ", got " << Shortest(v);
    }
  }
  for (const double v : {1e-5, 1.5e-5, 1.2345e-4, 0.001, 1e-100, 1.25e-100, 4.9e-324, 1e21,
                         123456789012345678901.0, -0.0, 0.0}) {
    EXPECT_EQ(Shortest(v), StdShortest(v));
    EXPECT_EQ(Shortest(-v), StdShortest(-v));
  }
}

// FormatShortest's own 128-bit path takes 2^-36 <= |v| < 2^49 (every binary exponent there is
// drawn evenly, which random bit patterns rarely do) and leaves ties and powers of two to
// std::to_chars. Mantissas with many trailing zero bits give exact ties and values a few digits
// long; nextafter neighbours of short decimals give intervals whose ends sit next to a
// candidate.
TEST(LogNumberTest, ShortestMatchesTheStandardLibraryAcrossItsOwnRange) {
  std::mt19937_64 random(3636);
  std::vector<double> values;
  for (int exponent = -40; exponent <= 52; ++exponent) {
    for (int i = 0; i < 12'000; ++i) {
      const std::uint64_t mantissa = random() & ((std::uint64_t{1} << 52U) - 1U);
      const int zero_bits = static_cast<int>(random() % 53U);
      const std::uint64_t bits = static_cast<std::uint64_t>(exponent + 1023) << 52U;
      values.push_back(FromBits(bits | mantissa));
      values.push_back(FromBits(bits | ((mantissa >> zero_bits) << zero_bits)));
    }
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::uniform_int_distribution<std::int64_t> significand(1, 99'999'999'999'999'999);
    for (int i = 0; i < 3'000; ++i) {
      const double v = static_cast<double>(significand(random) % kPow10Test[digits]) *
                       std::pow(10.0, static_cast<double>(static_cast<int>(random() % 30U)) - 20);
      values.push_back(v);
      values.push_back(std::nextafter(v, 0.0));
      values.push_back(std::nextafter(v, 1e300));
    }
  }
  int mismatches = 0;
  for (const double v : values) {
    for (const double signed_v : {v, -v}) {
      if (Shortest(signed_v) == StdShortest(signed_v)) continue;
      ADD_FAILURE() << "bits 0x" << std::hex << std::bit_cast<std::uint64_t>(signed_v)
                    << ": expected " << StdShortest(signed_v) << ", got " << Shortest(signed_v);
      if (++mismatches == 10) return;
    }
  }
}

// A row's text from FormatLogRow, whose memos copy a column's text while its value keeps its
// bits, is the row of cells written one by one: across held values, values that change every
// row, 0 and -0 (equal as doubles, not as bits), NaNs with other payloads, and the first row
// (the memos start as 0's text).
TEST(LogNumberTest, RowsWithRepeatedValuesMatchCellByCellFormatting) {
  constexpr std::size_t kColumns = 6;
  std::mt19937_64 random(36);
  const double quiet_nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> pool = {0.0, -0.0, 0.5, -0.3994140625, 1.7241130790320105, 12345,
                                    quiet_nan, FromBits(std::bit_cast<std::uint64_t>(quiet_nan) | 1U),
                                    -quiet_nan, 1e-300, 25.00025};
  std::vector<CellMemo> memos(kColumns);
  char text[kColumns * (kMaxNumberChars + 1) + kNumberScratchChars];
  double values[kColumns] = {};
  int mismatches = 0;
  for (int row = 0; row < 20'000 && mismatches < 10; ++row) {
    std::string expected;
    for (std::size_t c = 0; c < kColumns; ++c) {
      // Column c keeps its value with probability c / kColumns, else draws one (maybe the same).
      if (row == 0 || random() % kColumns >= c) values[c] = pool[random() % pool.size()];
      if (c != 0) expected += ',';
      expected += Reference(values[c]);
    }
    expected += '\n';
    const std::string actual(text, FormatLogRow(text, values, kColumns, memos.data()));
    if (actual != expected) {
      ++mismatches;
      ADD_FAILURE() << "row " << row << ": expected " << expected << "got " << actual;
    }
  }
}

}  // namespace
