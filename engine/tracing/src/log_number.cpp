#include "log_number.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace hiltwin::tracing::detail {
namespace {

constexpr std::uint64_t Pow10(int n) noexcept {
  std::uint64_t p = 1;
  for (int i = 0; i < n; ++i) p *= 10U;
  return p;
}

constexpr std::uint64_t kPow10[] = {Pow10(0),  Pow10(1),  Pow10(2),  Pow10(3),  Pow10(4),
                                    Pow10(5),  Pow10(6),  Pow10(7),  Pow10(8),  Pow10(9),
                                    Pow10(10), Pow10(11), Pow10(12), Pow10(13), Pow10(14),
                                    Pow10(15), Pow10(16), Pow10(17), Pow10(18), Pow10(19)};

/// Decimal digits of v (1 for 0): the bit width gives it within one (1233/4096 ~ log10 2).
/// v | 1 has the same count (10^k is even for k > 0) and makes 0 count as 1.
int DigitCount(std::uint64_t v) noexcept {
  const std::uint64_t odd = v | 1U;
  const int guess = static_cast<int>((std::bit_width(odd) * 1233U) >> 12U);
  return guess + (odd >= kPow10[guess] ? 1 : 0);
}

/// The 8 decimal digits of v < 10^8, leading zeros included, as ASCII in a little-endian word
/// (first digit in the lowest byte): each step splits every lane in two with a multiply and a
/// shift in place of a division (x * 10486 >> 20 = x / 100 for x < 10^4, x * 103 >> 10 =
/// x / 10 for x < 100), so 8 digits cost about as much as one pair by division.
static_assert(std::endian::native == std::endian::little, "EightDigits stores little-endian");
[[gnu::always_inline]] inline std::uint64_t EightDigits(std::uint32_t v) noexcept {
  const std::uint64_t halves = (v / 10'000U) | (static_cast<std::uint64_t>(v % 10'000U) << 32U);
  const std::uint64_t hundreds = ((halves * 10'486U) >> 20U) & 0x0000'007F'0000'007FU;
  const std::uint64_t pairs = hundreds | ((halves - hundreds * 100U) << 16U);
  const std::uint64_t tens = ((pairs * 103U) >> 10U) & 0x000F'000F'000F'000FU;
  return (tens | ((pairs - tens * 10U) << 8U)) + 0x3030'3030'3030'3030U;
}

void StoreEight(char* at, std::uint64_t digits) noexcept { std::memcpy(at, &digits, 8); }

/// Exactly `count` digits of v (v < 10^count, count <= 23), leading zeros included, from
/// `first`; returns the end. Eight digits at a time, the first count % 8 from a whole word:
/// that writes up to 7 bytes of scratch past the end (kNumberScratchChars), which the next
/// text written there replaces.
[[gnu::always_inline]] inline char* WriteZeroPadded(char* first, std::uint64_t v,
                                                    int count) noexcept {
  constexpr std::uint64_t kBlock = 100'000'000U;
  const int blocks = count / 8;
  const int lead = count % 8;
  std::uint64_t leading = v;  // the digits before the whole blocks, and the blocks' value
  std::uint64_t rest = 0;
  if (blocks == 1) {
    leading = v / kBlock;
    rest = v % kBlock;
  } else if (blocks == 2) {
    leading = v / (kBlock * kBlock);
    rest = v % (kBlock * kBlock);
  }
  if (lead == 1) {  // the most common leading part (a state's "1.", a time's "4."): no word
    *first++ = static_cast<char>('0' + leading);
  } else if (lead != 0) {
    StoreEight(first, EightDigits(static_cast<std::uint32_t>(leading)) >> (8 * (8 - lead)));
    first += lead;
  }
  if (blocks == 2) {
    StoreEight(first, EightDigits(static_cast<std::uint32_t>(rest / kBlock)));
    rest %= kBlock;
    first += 8;
  }
  if (blocks != 0) {
    StoreEight(first, EightDigits(static_cast<std::uint32_t>(rest)));
    first += 8;
  }
  return first;
}

char* WriteUnsigned(char* first, std::uint64_t v) noexcept {
  return WriteZeroPadded(first, v, DigitCount(v));
}

/// Writes the `count` digits of `digits` from first + 1, then moves the first `whole` of them
/// (1 <= whole < count) left by one and puts the decimal point after them: "d.ddd" in one pass
/// over the digits. Returns the end.
[[gnu::always_inline]] inline char* WriteWithPoint(char* first, std::uint64_t digits, int count,
                                                   int whole) noexcept {
  char* const end = WriteZeroPadded(first + 1, digits, count);
  if (whole == 1) {  // a state's "1.7241130790320105", a duty's "0.7998046875"
    first[0] = first[1];
    first[1] = '.';
  } else if (whole < 8) {  // a time's "25.00025", a state's "-10.939231391709034"
    // One word: bytes below `whole` from the digits one place to the right, then the point,
    // the bytes above it as they are (digits, or scratch past the end).
    std::uint64_t shifted = 0;
    std::uint64_t in_place = 0;
    std::memcpy(&shifted, first + 1, 8);
    std::memcpy(&in_place, first, 8);
    const unsigned point_bit = 8U * static_cast<unsigned>(whole);
    const std::uint64_t below = (std::uint64_t{1} << point_bit) - 1U;
    const std::uint64_t above = ~((below << 8U) | 0xFFU);
    const std::uint64_t word =
        (shifted & below) | (std::uint64_t{'.'} << point_bit) | (in_place & above);
    std::memcpy(first, &word, 8);
  } else {
    std::memmove(first, first + 1, static_cast<std::size_t>(whole));
    first[whole] = '.';
  }
  return end;
}

/// `units` · 10^-Decimals (units < 10^18) with its trailing zeros and a bare decimal point
/// removed, e.g. 4.99975, 12, -0.5, -0.
template <int Decimals>
char* WriteFixed(char* first, bool negative, std::uint64_t units) noexcept {
  constexpr std::uint64_t kScale = Pow10(Decimals);
  if (negative) *first++ = '-';
  if (units % kScale == 0) return WriteUnsigned(first, units / kScale);
  // All digits at once, at least one before the point ("0.000250" for 250 micro-units), then
  // the trailing zeros cut off: the fraction is not 0, so the point stays.
  const int count = std::max(DigitCount(units), Decimals + 1);
  char* end = WriteWithPoint(first, units, count, count - Decimals);
  while (end[-1] == '0') --end;
  return end;
}

/// x rounded to a whole number, ties to even, as std::nearbyint in the default rounding mode
/// (without its library call) for 0 <= x < 2^52: adding 2^52 leaves no fraction bits.
double RoundWhole(double x) noexcept {
  constexpr double kTwo52 = 4503599627370496.0;
  return (x + kTwo52) - kTwo52;
}

/// The exponent text of the scientific form: "e-05", "e+308".
char* WriteExponent(char* first, int exponent) noexcept {
  *first++ = 'e';
  *first++ = exponent < 0 ? '-' : '+';
  const auto magnitude = static_cast<std::uint64_t>(exponent < 0 ? -exponent : exponent);
  return WriteZeroPadded(first, magnitude, magnitude >= 100U ? 3 : 2);
}

/// |value| = digits · 10^exponent, digits without a trailing zero.
struct Decimal {
  std::uint64_t digits;
  int exponent;
};

constexpr std::uint64_t Pow5(int n) noexcept {
  std::uint64_t p = 1;
  for (int i = 0; i < n; ++i) p *= 5U;
  return p;
}

template <std::size_t... N>
constexpr std::array<std::uint64_t, sizeof...(N)> Pow5Table(std::index_sequence<N...>) noexcept {
  return {Pow5(static_cast<int>(N))...};
}

constexpr auto kPow5 = Pow5Table(std::make_index_sequence<28>());  // 5^27 < 2^63

__extension__ using U128 = unsigned __int128;  // GCC and Clang on 64-bit targets

/// The low 64 bits of x >> shift, for 0 < shift < 64 (two instructions: the compiler need not
/// handle shifts of 64 and more).
std::uint64_t ShiftRight(U128 x, int shift) noexcept {
  const auto low = static_cast<std::uint64_t>(x);
  const auto high = static_cast<std::uint64_t>(x >> 64U);
  return (low >> shift) | (high << (64 - shift));
}

/// The shortest digits for 2^-36 <= |value| < 2^49 (a twin's states: positions, angles,
/// speeds), exactly, with 128-bit integers: false (nothing written) outside that range, for a
/// power of two (its rounding interval is lopsided) and on an exact tie (FormatShortest leaves
/// those to the standard library). It computes what Ryu and Dragonbox define: the fewest
/// digits that read back as the value (a number strictly inside its rounding interval), the
/// nearest such to it. In this range no interval bound is a whole number of 17-digit units
/// (below), so whether the bounds belong to the interval (round-half-even reading) never
/// matters.
bool ShortestInRange(double value, Decimal& out) noexcept {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  const int binary_exponent = static_cast<int>((bits >> 52U) & 0x7FFU) - 1023;  // E
  const std::uint64_t fraction = bits & ((std::uint64_t{1} << 52U) - 1U);
  if (binary_exponent < -36 || binary_exponent >= 49 || fraction == 0) return false;
  // |value| = m · 2^(E - 52) with 2^52 <= m < 2^53, and 10^g <= 2^E < 10^(g + 1): the
  // multiply-shift is floor(E · log10 2) for |E| < 1650 (an arithmetic shift floors).
  const std::uint64_t m = fraction | (std::uint64_t{1} << 52U);
  const int g = (binary_exponent * 78'913) >> 18;
  // N = |value| · 10^q lies in [10^16, 2·10^17): 17 or 18 digits in front of the point, so
  // every candidate is a whole number. N = X / 2^s exactly, X = m · 5^q < 2^116, 2 <= s <= 61.
  const int q = 16 - g;  // 1 <= q <= 27
  const int s = 52 - binary_exponent - q;
  const std::uint64_t five_q = kPow5[static_cast<std::size_t>(q)];
  const U128 x = static_cast<U128>(m) * five_q;
  // The rounding interval is N ± 2^(E-53) · 10^q = (2X ± 5^q) / 2^(s+1). 5^q is odd and 2X
  // even, so neither bound is a multiple of 2^(s+1): no bound is a whole number, and
  // "a multiple of 10^k inside" is "floor(upper / 10^k) > floor(lower / 10^k)".
  std::uint64_t upper = ShiftRight(2 * x + five_q, s + 1);
  std::uint64_t lower = ShiftRight(2 * x - five_q, s + 1);
  // floor(2N), and whether 2N has a fraction: N's remainder to half a unit.
  const std::uint64_t twice = ShiftRight(x, s - 1);
  const bool inexact = (static_cast<std::uint64_t>(x) << (65 - s)) != 0;
  // The interval is more than one unit wide (2^(E-52) · 10^q > 10^16 / 2^53), so k = 0
  // always has one; the largest k gives the shortest text, as Ryu's digit removal does.
  int k = 0;
  std::uint64_t digits = twice >> 1U;  // floor(N / 10^k)
  while (upper / 10U != lower / 10U) {
    upper /= 10U;
    lower /= 10U;
    digits /= 10U;
    ++k;
  }
  // The nearest multiple of 10^k to N: inside too, as the interval is symmetric about N; and
  // with no trailing zero, else a multiple of 10^(k+1) would be inside. 2N - 2·digits·10^k
  // against 10^k, in half units: floor(2N) gives it, and its fraction breaks an equality.
  const std::uint64_t scale = kPow10[k];
  const std::uint64_t rest = twice - 2 * digits * scale;
  if (rest == scale && !inexact) return false;  // a tie: Ryu's own rule settles it
  if (rest >= scale) ++digits;
  out = {digits, k - q};
  return true;
}

}  // namespace

char* FormatShortest(char* first, double value) noexcept {
  Decimal decimal{};
  // Outside ShortestInRange's range (about one cell in a million in a twin's log: tiny values,
  // powers of two, ties) the standard library writes the text itself. fmt's Dragonbox, which
  // this took the digits from before, is fmt's internal API; std::to_chars costs about three
  // times as much, which no longer matters at that rate.
  if (!ShortestInRange(value, decimal)) {
    return std::to_chars(first, first + kMaxNumberChars, value).ptr;
  }
  const std::uint64_t digits = decimal.digits;
  const int exponent = decimal.exponent;  // value = ±digits · 10^exponent, no trailing zero
  if (exponent >= 0) {
    // Values >= 10^16 or with no fraction: never in a log cell (the callers print whole
    // numbers as such), so the standard library's layout of trailing zeros is kept as is.
    return std::to_chars(first, first + kMaxNumberChars, value).ptr;
  }
  if (std::signbit(value)) *first++ = '-';
  const int count = DigitCount(digits);
  const int scientific_exponent = exponent + count - 1;
  const int exponent_chars = scientific_exponent <= -100 || scientific_exponent >= 100 ? 3 : 2;
  const int scientific_chars = count + (count > 1 ? 1 : 0) + 2 + exponent_chars;
  const int decimals = -exponent;
  if (count > decimals) {  // d.ddd: always shorter than d.ddde+XX
    return WriteWithPoint(first, digits, count, count - decimals);
  }
  if (2 + decimals <= scientific_chars) {  // 0.000ddd, fixed on a tie as std::to_chars
    *first++ = '0';
    *first++ = '.';
    return WriteZeroPadded(first, digits, decimals);
  }
  // d.ddde-XX: the digits one place to the right, then the first moved before the point.
  char* const end = WriteZeroPadded(first + 1, digits, count);
  first[0] = first[1];
  if (count > 1) {
    first[1] = '.';
    return WriteExponent(end, scientific_exponent);
  }
  return WriteExponent(first + 1, scientific_exponent);
}

char* FormatLogNumber(char* first, double value) noexcept {
  const double magnitude = std::fabs(value);
  if (!(magnitude <= 1.7976931348623157e308)) {  // NaN fails every comparison
    if (std::isnan(value)) return std::copy_n("NaN", 3, first);
    if (value < 0) *first++ = '-';
    return std::copy_n("Inf", 3, first);
  }
  const bool negative = std::signbit(value);
  if (magnitude == 0.0) {  // a third of a twin's cells: signals that are not in use
    if (negative) *first++ = '-';
    *first++ = '0';
    return first;
  }
  // Shortest round-trip formatting is the expensive case, and the writer thread formats every
  // cell of every row. Three exact shortcuts cover most cells of a twin's log: values with at
  // most 6 decimals (time stamps, microseconds, counters), multiples of 2^-11 (PWM duty is
  // value / 2048, whose decimal expansion ends after 11 places) and whole numbers up to 2^53
  // are printed from integers. Each prints the value's exact decimal expansion, which reads
  // back as the very same double, so the file stays bit-exact.
  if (magnitude >= 9007199254740992.0) return FormatShortest(first, value);
  // 2^53: every whole double below is exact. Whole numbers first (cycle numbers, encoder
  // counts): below 10^6 the 6-decimal shortcut would write the same text, for more work.
  const auto whole = static_cast<std::int64_t>(magnitude);
  if (static_cast<double>(whole) == magnitude) {
    if (negative) *first++ = '-';
    return WriteUnsigned(first, static_cast<std::uint64_t>(whole));
  }
  if (magnitude < 1e6) {
    const double micros = RoundWhole(magnitude * 1e6);
    if (micros / 1e6 == magnitude) {
      // int64: one conversion instruction (micros < 10^12); uint64 takes a branch more.
      return WriteFixed<6>(first, negative, static_cast<std::uint64_t>(
                                                static_cast<std::int64_t>(micros)));
    }
    const double steps = magnitude * 2048.0;  // exact: a power-of-two scale, below 2^31
    const auto whole_steps = static_cast<std::int64_t>(steps);
    if (static_cast<double>(whole_steps) == steps) {
      // n / 2^11 = n · 5^11 / 10^11; below 10^6 · 2^11 · 5^11 < 2^57, no overflow.
      return WriteFixed<11>(first, negative,
                            static_cast<std::uint64_t>(whole_steps) * 48'828'125U);
    }
  }
  return FormatShortest(first, value);
}

char* FormatLogRow(char* first, const double* values, std::size_t count,
                   CellMemo* memos) noexcept {
  constexpr std::size_t kCellRoom = sizeof(CellMemo::text);
  for (std::size_t c = 0; c < count; ++c) {
    CellMemo& memo = memos[c];
    const auto bits = std::bit_cast<std::uint64_t>(values[c]);
    if (bits == memo.bits) {
      // A fixed-size copy (two vector moves): the bytes past the text are scratch, which the
      // comma and the next cell overwrite, as after FormatLogNumber.
      std::memcpy(first, memo.text, kCellRoom);
      first += memo.length;
    } else {
      char* const end = FormatLogNumber(first, values[c]);
      std::memcpy(memo.text, first, kCellRoom);
      memo.bits = bits;
      memo.length = static_cast<std::size_t>(end - first);
      first = end;
    }
    *first++ = ',';
  }
  first[-1] = '\n';
  return first;
}

}  // namespace hiltwin::tracing::detail
