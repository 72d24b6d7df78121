#include "hiltwin/app_relbot/input_profile.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace hiltwin::app {
namespace {

constexpr std::array<std::string_view, 1> kBuiltinNames{"openloop"};

constexpr const char* kCsvForm =
    "a profile CSV has the header 'time,left,right' and then rows 'seconds,duty,duty' with "
    "time not decreasing (repeat a time once for a sudden step) and duty in [-1, 1]";

bool DutyOk(double duty) { return std::isfinite(duty) && duty >= -1.0 && duty <= 1.0; }

std::string_view Trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) {
    text.remove_suffix(1);
  }
  return text;
}

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

struct Field {
  std::string_view text;  // trimmed
  std::size_t column;     // 1-based column of the field's first character (after trimming)
};

// Splits one line on commas; columns count from 1 as editors show them.
std::vector<Field> SplitFields(std::string_view line) {
  std::vector<Field> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    std::string_view raw = line.substr(start, end - start);
    std::size_t lead = 0;
    while (lead < raw.size() && std::isspace(static_cast<unsigned char>(raw[lead]))) ++lead;
    fields.push_back(Field{Trim(raw), start + lead + 1});
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

[[noreturn]] void Fail(std::string_view source, std::size_t line, std::size_t column,
                       const std::string& what, std::string_view todo) {
  std::ostringstream out;
  out << source << ':' << line << ':' << column << ": " << what << "; " << todo;
  throw ProfileError(out.str());
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

Duty InputProfile::At(double t_s) const noexcept {
  if (!std::isfinite(t_s)) return Duty{};
  if (t_s <= 0.0) return knots_.front().duty;
  const double period = period_s();
  double local_s = t_s - std::floor(t_s / period) * period;
  if (!(local_s < period) || local_s < 0.0) local_s = 0.0;  // rounding at a period boundary
  // First knot strictly after local_s: the segment [it-1, it] holds local_s, and at a step
  // (two knots with one time) it-1 is the later knot, so the profile is right-continuous.
  const auto it = std::upper_bound(
      knots_.begin(), knots_.end(), local_s,
      [](double t, const ProfileKnot& knot) { return t < knot.time_s; });
  if (it == knots_.begin()) return knots_.front().duty;
  if (it == knots_.end()) return knots_.back().duty;
  const ProfileKnot& a = *(it - 1);
  const ProfileKnot& b = *it;
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
  std::vector<ProfileKnot> knots;
  bool have_header = false;
  std::size_t line_number = 0;
  std::size_t last_line = 0;
  std::size_t same_time_count = 0;
  std::size_t pos = 0;
  // Spreadsheet programs often start a CSV with a UTF-8 byte-order mark; it is not data.
  if (text.starts_with("\xEF\xBB\xBF")) pos = 3;
  while (pos <= text.size()) {
    const std::size_t newline = text.find('\n', pos);
    const std::size_t end = newline == std::string_view::npos ? text.size() : newline;
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string_view trimmed = Trim(line);
    if (trimmed.empty() || trimmed.front() == '#') {
      if (newline == std::string_view::npos) break;
      continue;
    }
    const std::vector<Field> fields = SplitFields(line);
    if (!have_header) {
      constexpr std::array<std::string_view, 3> kExpected{"time", "left", "right"};
      for (std::size_t i = 0; i < kExpected.size(); ++i) {
        const bool ok = i < fields.size() &&
                        (EqualsIgnoreCase(fields[i].text, kExpected[i]) ||
                         (i == 0 && EqualsIgnoreCase(fields[i].text, "time_s")));
        if (!ok) {
          const std::size_t column = i < fields.size() ? fields[i].column : line.size() + 1;
          Fail(source_name, line_number, column,
               "expected the header 'time,left,right', found '" + std::string(trimmed) + "'",
               "add that header as the first line (time in seconds, duties in [-1, 1])");
        }
      }
      if (fields.size() > kExpected.size()) {
        Fail(source_name, line_number, fields[3].column,
             "the header has more than the three columns time,left,right",
             "remove the extra columns");
      }
      have_header = true;
      if (newline == std::string_view::npos) break;
      continue;
    }
    if (fields.size() != 3) {
      const std::size_t column =
          fields.size() > 3 ? fields[3].column : line.size() + 1;
      Fail(source_name, line_number, column,
           "expected 3 values (time,left,right), found " + std::to_string(fields.size()),
           kCsvForm);
    }
    std::array<double, 3> values{};
    constexpr std::array<std::string_view, 3> kWhat{"time", "left duty", "right duty"};
    for (std::size_t i = 0; i < 3; ++i) {
      std::string_view number = fields[i].text;
      if (!number.empty() && number.front() == '+') number.remove_prefix(1);
      const char* first = number.data();
      const char* last = number.data() + number.size();
      const auto [ptr, ec] = std::from_chars(first, last, values[i]);
      if (number.empty() || ec != std::errc() || ptr != last) {
        Fail(source_name, line_number, fields[i].column,
             std::string(kWhat[i]) + " '" + std::string(fields[i].text) + "' is not a number",
             kCsvForm);
      }
      if (!std::isfinite(values[i])) {
        Fail(source_name, line_number, fields[i].column,
             std::string(kWhat[i]) + " '" + std::string(fields[i].text) +
                 "' is not finite (NaN or infinity)",
             "replace it with a finite number");
      }
    }
    const double time_s = values[0];
    if (time_s < 0.0) {
      Fail(source_name, line_number, fields[0].column,
           "time " + std::string(fields[0].text) + " s is negative",
           "profiles start at time 0 or later");
    }
    for (std::size_t i = 1; i < 3; ++i) {
      if (!DutyOk(values[i])) {
        Fail(source_name, line_number, fields[i].column,
             std::string(kWhat[i]) + " " + std::string(fields[i].text) +
                 " is outside [-1, 1]",
             "duty is a fraction of the supply voltage; scale the column into [-1, 1]");
      }
    }
    if (!knots.empty()) {
      const double previous_s = knots.back().time_s;
      if (time_s < previous_s) {
        std::ostringstream what;
        what << "time " << fields[0].text << " s is earlier than the previous row's " << previous_s
             << " s (line " << last_line << ")";
        Fail(source_name, line_number, fields[0].column, what.str(),
             "sort the rows by time; times must not decrease");
      }
      same_time_count = time_s == previous_s ? same_time_count + 1 : 0;
      if (same_time_count >= 2) {
        Fail(source_name, line_number, fields[0].column,
             "a third row with time " + std::string(fields[0].text) + " s",
             "a sudden step is two rows with the same time (before and after); remove the "
             "extra row");
      }
    }
    knots.push_back(ProfileKnot{time_s, Duty{values[1], values[2]}});
    last_line = line_number;
    if (newline == std::string_view::npos) break;
  }
  if (!have_header) {
    Fail(source_name, 1, 1, "the file is empty", kCsvForm);
  }
  if (knots.size() < 2 || !(knots.back().time_s > 0.0)) {
    Fail(source_name, line_number, 1,
         "the profile needs at least two rows and a last time > 0 (it has " +
             std::to_string(knots.size()) + " row(s))",
         "add a row for the end time; the profile repeats with that period");
  }
  return InputProfile::FromKnots(std::string(source_name), std::move(knots));
}

InputProfile LoadCsvProfile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw ProfileError(path.string() + ": cannot read the input profile (" +
                       std::string(std::strerror(errno)) + "); check the path");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return ParseCsvProfile(text.str(), path.string());
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
