#pragma once
// The table hiltwin_bench_cycle prints: each component of a twin cycle with its figure per
// cycle, its share of the whole virtual-clock cycle, and the target it has (issue 36: the whole
// cycle <= 1,800 instructions without the log, the log writer <= 2,500 per 15-column row) with
// the verdict. Kept apart from the benchmark so that the arithmetic is unit-tested
// (tests/unit/bench) and docs/BENCHMARKS.md's quoted table is checked against this format.

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hiltwin::bench {

/// One component: what it is, its figure per cycle (instructions, or ns without valgrind) and
/// the target that figure has, if any.
struct CycleComponent {
  std::string name;
  double per_cycle = 0.0;
  std::optional<double> target;
};

/// `part` as a percentage of `whole`; throws std::invalid_argument when `whole` is not above 0.
inline double SharePct(double part, double whole) {
  if (!(whole > 0.0)) throw std::invalid_argument("SharePct: the whole cycle is not above 0");
  return 100.0 * part / whole;
}

/// "met" when the figure is at most the target, "NOT met" above it, "-" without a target.
inline const char* VerdictOf(const CycleComponent& component) {
  if (!component.target) return "-";
  return component.per_cycle <= *component.target ? "met" : "NOT met";
}

/// 1800 -> "1,800": targets as the docs write them.
inline std::string Grouped(double figure) {
  std::string digits = std::to_string(std::llround(figure));
  const std::size_t first = digits.front() == '-' ? 1 : 0;
  for (int i = static_cast<int>(digits.size()) - 3; i > static_cast<int>(first); i -= 3) {
    digits.insert(static_cast<std::size_t>(i), ",");
  }
  return digits;
}

/// The column heads, then one line per component ("  <name padded> <figure> <share> % <target>
/// <verdict>"), the share of `whole` (the whole cycle's figure). `unit` names the figure.
inline std::vector<std::string> FormatCycleTable(const std::vector<CycleComponent>& components,
                                                 double whole, const char* unit) {
  std::vector<std::string> lines;
  char line[192];
  std::snprintf(line, sizeof line, "  %-46s %12s %8s %10s  %s", "component", unit, "share",
                "target", "verdict");
  lines.emplace_back(line);
  for (const CycleComponent& c : components) {
    const std::string target = c.target ? "<= " + Grouped(*c.target) : "-";
    std::snprintf(line, sizeof line, "  %-46s %12.1f %7.1f %% %10s  %s", c.name.c_str(),
                  c.per_cycle, SharePct(c.per_cycle, whole), target.c_str(), VerdictOf(c));
    lines.emplace_back(line);
  }
  return lines;
}

}  // namespace hiltwin::bench
