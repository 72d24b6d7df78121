#include "hiltwin/relbot/input_profile.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <utility>

#include "hiltwin/tracing/csv.h"

namespace hiltwin::app {
namespace {

constexpr std::array<std::string_view, 1> kBuiltinNames{"openloop"};

constexpr const char* kCsvForm =
    "a profile CSV has the header 'time,left,right' and then rows 'seconds,duty,duty' with "
    "time not decreasing (repeat a time once for a sudden step) and duty in [-1, 1]";

bool DutyOk(double duty) { return std::isfinite(duty) && duty >= -1.0 && duty <= 1.0; }

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// Where the duties are: columns 2 and 3 of a profile 'time,left,right', or the duty_left and
// duty_right columns of a hiltwin log (`hiltwin ecs --mode openloop` logs the duty on the wire
// there, `hiltwin run` the duty it read), whose other columns are ignored. So an ECS log
// replays as the input of a reference run without editing (thesis §5.2).
struct DutyColumns {
  std::size_t left = 1;
  std::size_t right = 2;
};

std::optional<DutyColumns> FindLogDutyColumns(const analysis::CsvTable& table) {
  std::optional<std::size_t> left;
  std::optional<std::size_t> right;
  for (std::size_t i = 1; i < table.names.size(); ++i) {
    if (EqualsIgnoreCase(table.names[i], "duty_left")) left = i;
    if (EqualsIgnoreCase(table.names[i], "duty_right")) right = i;
  }
  if (!left || !right) return std::nullopt;
  return DutyColumns{*left, *right};
}

DutyColumns DutyColumnsOf(const analysis::CsvTable& table) {
  return FindLogDutyColumns(table).value_or(DutyColumns{});
}

// The header names the columns, so a file with left and right swapped or a log of another
// kind is refused instead of played: time (or time_s), left, right, in any letter case; or
// time and a log's duty_left and duty_right.
void CheckProfileHeader(const analysis::CsvTable& table, std::size_t line) {
  constexpr std::string_view kAdvice =
      "; add that header as the first line (time in seconds, duties in [-1, 1])";
  const std::string_view expected =
      "expected the header 'time,left,right' (or a hiltwin log with the columns duty_left and "
      "duty_right)";
  if (!table.has_header) {
    throw analysis::InputError(analysis::CsvLocation(table.path, line, 1) + ": " +
                               std::string(expected) + ", found a row of numbers" +
                               std::string(kAdvice));
  }
  const bool is_log = FindLogDutyColumns(table).has_value();
  constexpr std::array<std::string_view, 3> kNames{"time", "left", "right"};
  for (std::size_t i = 0; i < (is_log ? 1 : kNames.size()); ++i) {
    const bool ok = i < table.names.size() &&
                    (EqualsIgnoreCase(table.names[i], kNames[i]) ||
                     (i == 0 && EqualsIgnoreCase(table.names[i], "time_s")));
    if (!ok) {
      std::string found;
      for (const std::string& name : table.names) found += (found.empty() ? "" : ",") + name;
      throw analysis::InputError(analysis::CsvLocation(table.path, line, i + 1) + ": " +
                                 std::string(expected) + ", found '" + found + "'" +
                                 std::string(kAdvice));
    }
  }
  if (!is_log && table.names.size() > kNames.size()) {
    throw analysis::InputError(analysis::CsvLocation(table.path, line, kNames.size() + 1) +
                               ": the header has more than the three columns time,left,right; "
                               "remove the extra columns (a hiltwin log is read by its "
                               "duty_left and duty_right columns)");
  }
}

analysis::CsvRules ProfileRules() {
  analysis::CsvRules rules;
  rules.time_order = analysis::TimeOrder::kStepsAllowed;
  rules.purpose = "for an input profile (a start and an end time; it repeats with the last time "
                  "as its period)";
  rules.check_layout = CheckProfileHeader;
  return rules;
}

// What the reader cannot know about a profile: it starts at 0 s or later, duties are
// fractions of the supply voltage, and the period is > 0.
std::vector<ProfileKnot> KnotsOf(const analysis::CsvTable& table) {
  const DutyColumns duty = DutyColumnsOf(table);
  const std::array<std::size_t, 2> columns{duty.left, duty.right};
  constexpr std::array<std::string_view, 2> kWhat{"left duty", "right duty"};
  std::vector<ProfileKnot> knots;
  for (std::size_t row = 0; row < table.rows(); ++row) {
    const double time_s = table.columns[0][row];
    if (time_s < 0.0) {
      throw analysis::InputError(table.Where(row, 0) + ": time " + analysis::NumberText(time_s) +
                                 " s is negative; profiles start at time 0 or later");
    }
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const std::size_t c = columns[i];
      if (!DutyOk(table.columns[c][row])) {
        throw analysis::InputError(
            table.Where(row, c) + ": " + std::string(kWhat[i]) + " " +
            analysis::NumberText(table.columns[c][row]) +
            " is outside [-1, 1]; duty is a fraction of the supply voltage: scale the column "
            "into [-1, 1]");
      }
    }
    knots.push_back(
        ProfileKnot{time_s, Duty{table.columns[duty.left][row], table.columns[duty.right][row]}});
  }
  if (!(knots.back().time_s > 0.0)) {
    throw analysis::InputError(table.Where(table.rows() - 1, 0) +
                               ": the last time is 0 s; the profile repeats with the last time "
                               "as its period: add a row for the end time");
  }
  return knots;
}

// One place where reader errors become profile errors, for text and files alike.
template <typename ReadTable>
InputProfile ProfileFromCsv(std::string name, ReadTable read_table) {
  try {
    return InputProfile::FromKnots(std::move(name), KnotsOf(read_table()));
  } catch (const analysis::InputError& error) {
    throw ProfileError(error.what());
  }
}

}  // namespace

InputProfile InputProfile::FromKnots(std::string name, std::vector<ProfileKnot> knots) {
  auto fail = [&name](std::size_t index, const std::string& what) {
    throw ProfileError("input profile '" + name + "', knot " + std::to_string(index) + ": " +
                       what + "; " + kCsvForm);
  };
  if (knots.size() < 2) {
    throw ProfileError("input profile '" + name + "' has " + std::to_string(knots.size()) +
                       " knot(s); it needs at least two (a start and an end time)");
  }
  for (std::size_t i = 0; i < knots.size(); ++i) {
    const ProfileKnot& k = knots[i];
    if (!std::isfinite(k.time_s) || k.time_s < 0.0) fail(i, "time must be finite and >= 0");
    if (!DutyOk(k.duty.left) || !DutyOk(k.duty.right)) {
      fail(i, "duty must be finite and within [-1, 1]");
    }
    if (i > 0 && k.time_s < knots[i - 1].time_s) fail(i, "time decreases");
    if (i > 1 && k.time_s == knots[i - 2].time_s) {
      fail(i, "three knots share one time; a step needs exactly two");
    }
  }
  if (!(knots.back().time_s > 0.0)) fail(knots.size() - 1, "the last time must be > 0");
  return InputProfile(std::move(name), std::move(knots));
}

// The upper bound is the one index with knot[index - 1] <= local_s < knot[index] (the ends
// counting as -inf and +inf), so a hint that passes this test is the search's answer.
[[gnu::always_inline]] inline bool InputProfile::IsKnotAfter(double local_s,
                                                            std::size_t index) const noexcept {
  return index <= knots_.size() && (index == 0 || knots_[index - 1].time_s <= local_s) &&
         (index == knots_.size() || local_s < knots_[index].time_s);
}

// Inline in At, which a player calls at every controller sample.
[[gnu::always_inline]] inline std::size_t InputProfile::KnotAfter(
    double local_s, std::size_t hint) const noexcept {
  if (IsKnotAfter(local_s, hint)) return hint;  // still in the same segment
  if (IsKnotAfter(local_s, hint + 1)) return hint + 1;  // moved on into the next one
  const auto it = std::upper_bound(
      knots_.begin(), knots_.end(), local_s,
      [](double t, const ProfileKnot& knot) { return t < knot.time_s; });
  return static_cast<std::size_t>(it - knots_.begin());
}

Duty InputProfile::At(double t_s) const noexcept {
  std::size_t cursor = 0;
  return At(t_s, cursor);
}

Duty InputProfile::At(double t_s, std::size_t& cursor) const noexcept {
  if (!std::isfinite(t_s)) return Duty{};
  if (t_s <= 0.0) return knots_.front().duty;
  const double period = period_s();
  double local_s = t_s - std::floor(t_s / period) * period;
  if (!(local_s < period) || local_s < 0.0) local_s = 0.0;  // rounding at a period boundary
  // First knot strictly after local_s: the segment [it-1, it] holds local_s, and at a step
  // (two knots with one time) it-1 is the later knot, so the profile is right-continuous.
  const std::size_t it = KnotAfter(local_s, cursor);
  cursor = it;
  if (it == 0) return knots_.front().duty;
  if (it == knots_.size()) return knots_.back().duty;
  const ProfileKnot& a = knots_[it - 1];
  const ProfileKnot& b = knots_[it];
  const double f = (local_s - a.time_s) / (b.time_s - a.time_s);
  return Duty{a.duty.left + f * (b.duty.left - a.duty.left),
              a.duty.right + f * (b.duty.right - a.duty.right)};
}

std::span<const std::string_view> BuiltinProfileNames() noexcept { return kBuiltinNames; }

InputProfile OpenLoopProfile() {
  // After thesis fig. 5.1 (about 36 s, sudden and gradual changes "to excite all aspects of the
  // model"); the figure's exact values are not published, so this profile is our own. It
  // starts and ends at rest so that repeating it is continuous. Segments, (left, right):
  std::vector<ProfileKnot> knots{
      {0.0, {0.0, 0.0}},   {1.0, {0.0, 0.0}},    // rest
      {1.0, {0.4, 0.4}},   {3.0, {0.4, 0.4}},    // step: straight ahead
      {6.0, {1.0, 1.0}},   {8.0, {1.0, 1.0}},    // ramp to full duty, hold
      {8.0, {-0.5, -0.5}}, {10.0, {-0.5, -0.5}}, // sudden reversal
      {12.0, {0.0, 0.0}},  {13.0, {0.0, 0.0}},   // ramp to rest
      {13.0, {0.6, -0.6}}, {15.0, {0.6, -0.6}},  // step: turn in place clockwise
      {15.0, {-0.3, 0.3}}, {17.0, {-0.3, 0.3}},  // step: turn back slower
      {20.0, {0.8, 0.4}},  {23.0, {0.8, 0.4}},   // ramp through zero into a right arc
      {23.0, {0.2, 0.2}},                        // step down
      {27.0, {-1.0, -1.0}}, {29.0, {-1.0, -1.0}}, // slow ramp through standstill to full reverse
      {29.0, {0.3, 0.7}},  {32.0, {0.3, 0.7}},   // step into a left arc
      {34.0, {0.0, 0.0}},                        // ramp to rest
      {34.5, {0.0, 0.0}},  {34.5, {0.1, 0.1}},   // small duty where friction matters most
      {35.5, {0.1, 0.1}},  {35.5, {0.0, 0.0}},   // and off
      {36.0, {0.0, 0.0}},
  };
  return InputProfile::FromKnots("openloop", std::move(knots));
}

InputProfile ParseCsvProfile(std::string_view text, std::string_view source_name) {
  const std::string name(source_name);
  return ProfileFromCsv(name, [&] { return analysis::ParseCsv(text, name, ProfileRules()); });
}

InputProfile LoadCsvProfile(const std::filesystem::path& path) {
  const std::string name = path.string();
  return ProfileFromCsv(name, [&] { return analysis::ReadCsv(name, ProfileRules()); });
}

InputProfile LoadInputProfile(std::string_view name_or_path) {
  if (name_or_path == "openloop") return OpenLoopProfile();
  std::error_code ec;
  const std::filesystem::path path{std::string(name_or_path)};
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string names;
    for (std::string_view name : kBuiltinNames) names += (names.empty() ? "" : ", ") + std::string(name);
    throw ProfileError("input profile '" + std::string(name_or_path) +
                       "' is neither a built-in profile (" + names +
                       ") nor a readable CSV file; give one of those names or the path of a "
                       "CSV with the header time,left,right");
  }
  return LoadCsvProfile(path);
}

}  // namespace hiltwin::app
