#include "hiltwin/relbot/setpoint_profile.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <utility>

#include "hiltwin/tracing/csv.h"

namespace hiltwin::app {
namespace {

constexpr std::array<std::string_view, 1> kBuiltinNames{"closedloop"};

constexpr const char* kCsvForm =
    "a setpoint CSV has the header 'time,left_m,right_m' and then rows 'seconds,metres,metres' "
    "(wheel travel from the start of the run) with time not decreasing (repeat a time once for "
    "a sudden step)";

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string JoinedNames(const analysis::CsvTable& table) {
  std::string found;
  for (const std::string& name : table.names) found += (found.empty() ? "" : ",") + name;
  return found;
}

// The header names the columns and their unit, so a duty profile or a log given by mistake is
// refused instead of being played as metres.
void CheckSetpointHeader(const analysis::CsvTable& table, std::size_t line) {
  constexpr std::string_view kExpected = "expected the header 'time,left_m,right_m'";
  constexpr std::string_view kAdvice =
      "; add that header as the first line (time in seconds, wheel travel in metres)";
  if (!table.has_header) {
    throw analysis::InputError(analysis::CsvLocation(table.path, line, 1) + ": " +
                               std::string(kExpected) + ", found a row of numbers" +
                               std::string(kAdvice));
  }
  constexpr std::array<std::string_view, 3> kNames{"time", "left_m", "right_m"};
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    const bool ok =
        i < table.names.size() && (EqualsIgnoreCase(table.names[i], kNames[i]) ||
                                   (i == 0 && EqualsIgnoreCase(table.names[i], "time_s")));
    if (!ok) {
      throw analysis::InputError(analysis::CsvLocation(table.path, line, i + 1) + ": " +
                                 std::string(kExpected) + ", found '" + JoinedNames(table) + "'" +
                                 std::string(kAdvice));
    }
  }
  if (table.names.size() > kNames.size()) {
    throw analysis::InputError(analysis::CsvLocation(table.path, line, kNames.size() + 1) +
                               ": the header has more than the three columns "
                               "time,left_m,right_m; remove the extra columns");
  }
}

analysis::CsvRules SetpointRules() {
  analysis::CsvRules rules;
  rules.time_order = analysis::TimeOrder::kStepsAllowed;
  rules.purpose =
      "for a setpoint profile (a start and an end time; after the end the last "
      "setpoint holds)";
  rules.check_layout = CheckSetpointHeader;
  return rules;
}

std::vector<SetpointKnot> KnotsOf(const analysis::CsvTable& table) {
  std::vector<SetpointKnot> knots;
  knots.reserve(table.rows());
  for (std::size_t row = 0; row < table.rows(); ++row) {
    const double time_s = table.columns[0][row];
    if (time_s < 0.0) {
      throw analysis::InputError(table.Where(row, 0) + ": time " + analysis::NumberText(time_s) +
                                 " s is negative; setpoint profiles start at time 0 or later");
    }
    knots.push_back(SetpointKnot{time_s,
                                 WheelPositions{table.columns[1][row], table.columns[2][row]},
                                 SegmentShape::kLinear});
  }
  if (!(knots.back().time_s > 0.0)) {
    throw analysis::InputError(table.Where(table.rows() - 1, 0) +
                               ": the last time is 0 s; add a row for the end time (after it "
                               "the last setpoint holds)");
  }
  return knots;
}

template <typename ReadTable>
SetpointProfile ProfileFromCsv(const std::string& name, const ReadTable& read_table) {
  try {
    return SetpointProfile::FromKnots(name, KnotsOf(read_table()));
  } catch (const analysis::InputError& error) {
    throw ProfileError(error.what());
  }
}

double Blend(SegmentShape shape, double s) noexcept {
  if (shape == SegmentShape::kLinear) return s;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  return s - std::sin(kTwoPi * s) / kTwoPi;
}

}  // namespace

SetpointProfile SetpointProfile::FromKnots(std::string name, std::vector<SetpointKnot> knots) {
  auto fail = [&name](std::size_t index, const std::string& what) {
    throw ProfileError("setpoint profile '" + name + "', knot " + std::to_string(index) + ": " +
                       what + "; " + kCsvForm);
  };
  if (knots.size() < 2) {
    throw ProfileError("setpoint profile '" + name + "' has " + std::to_string(knots.size()) +
                       " knot(s); it needs at least two (a start and an end time)");
  }
  for (std::size_t i = 0; i < knots.size(); ++i) {
    const SetpointKnot& k = knots[i];
    if (!std::isfinite(k.time_s) || k.time_s < 0.0) fail(i, "time must be finite and >= 0");
    if (!std::isfinite(k.position.left_m) || !std::isfinite(k.position.right_m)) {
      fail(i, "positions must be finite numbers of metres");
    }
    if (i > 0 && k.time_s < knots[i - 1].time_s) fail(i, "time decreases");
    if (i > 1 && k.time_s == knots[i - 2].time_s) {
      fail(i, "three knots share one time; a step needs exactly two");
    }
  }
  if (!(knots.back().time_s > 0.0)) fail(knots.size() - 1, "the last time must be > 0");
  return SetpointProfile(std::move(name), std::move(knots));
}

WheelPositions SetpointProfile::At(double t_s) const noexcept {
  if (!std::isfinite(t_s)) return knots_.front().position;
  // First knot strictly after t_s: the segment [it-1, it] holds t_s, and at a step (two knots
  // with one time) it-1 is the later knot, so the profile is right-continuous.
  const auto it =
      std::upper_bound(knots_.begin(), knots_.end(), t_s,
                       [](double t, const SetpointKnot& knot) { return t < knot.time_s; });
  if (it == knots_.begin()) return knots_.front().position;
  if (it == knots_.end()) return knots_.back().position;
  const SetpointKnot& a = *(it - 1);
  const SetpointKnot& b = *it;
  const double f = Blend(a.shape, (t_s - a.time_s) / (b.time_s - a.time_s));
  return WheelPositions{a.position.left_m + f * (b.position.left_m - a.position.left_m),
                        a.position.right_m + f * (b.position.right_m - a.position.right_m)};
}

SetpointProfile ClosedLoopProfile() {
  constexpr double kMoveStartS = kClosedLoopRestS;
  constexpr double kMoveEndS = kClosedLoopRestS + kClosedLoopMoveS;
  constexpr double kD = kClosedLoopDistanceM;
  std::vector<SetpointKnot> knots{
      {0.0, {0.0, 0.0}, SegmentShape::kLinear},          // rest: the loop starts from standstill
      {kMoveStartS, {0.0, 0.0}, SegmentShape::kSmooth},  // one smooth move, both wheels
      {kMoveEndS, {kD, kD}, SegmentShape::kLinear},      // rest: the integral settles
      {kMoveEndS + kClosedLoopSettleS, {kD, kD}, SegmentShape::kLinear},
  };
  return SetpointProfile::FromKnots("closedloop", std::move(knots));
}

std::span<const std::string_view> BuiltinSetpointNames() noexcept { return kBuiltinNames; }

SetpointProfile ParseCsvSetpoints(std::string_view text, std::string_view source_name) {
  const std::string name(source_name);
  return ProfileFromCsv(name, [&] { return analysis::ParseCsv(text, name, SetpointRules()); });
}

SetpointProfile LoadCsvSetpoints(const std::filesystem::path& path) {
  const std::string name = path.string();
  return ProfileFromCsv(name, [&] { return analysis::ReadCsv(name, SetpointRules()); });
}

SetpointProfile LoadSetpointProfile(std::string_view name_or_path) {
  if (name_or_path == "closedloop") return ClosedLoopProfile();
  std::error_code ec;
  const std::filesystem::path path{std::string(name_or_path)};
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string names;
    for (std::string_view name : kBuiltinNames) {
      names += (names.empty() ? "" : ", ") + std::string(name);
    }
    throw ProfileError("setpoint profile '" + std::string(name_or_path) +
                       "' is neither a built-in profile (" + names +
                       ") nor a readable CSV file; give one of those names or the path of a CSV "
                       "with the header time,left_m,right_m");
  }
  return LoadCsvSetpoints(path);
}

}  // namespace hiltwin::app
