#pragma once
/// Duty-cycle input profiles for the RELbot twin: the built-in `openloop` profile (after thesis
/// fig. 5.1) and user CSV files `time,left,right`. A profile is a continuous-time signal:
/// knots joined by straight lines, a repeated time marks a sudden step, and the whole profile
/// repeats with its period. Sampling and holding the signal (as a PWM does) is the job of
/// whoever plays it (the ECS side at its own rate), not of the profile.

#include <cstddef>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hiltwin::app {

/// Duty cycle of both drivetrains, each a fraction of the supply voltage in [-1, 1].
struct Duty {
  double left = 0.0;   ///< left wheel, + drives forward
  double right = 0.0;  ///< right wheel, + drives forward
};

/// One corner of a piecewise-linear profile.
struct ProfileKnot {
  double time_s = 0.0;  ///< time since the start of one repetition
  Duty duty;            ///< duty at time_s (right-continuous at steps)
};

/// A bad profile (file or knots); the message says file:line:column, what and what to do.
class ProfileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A piecewise-linear, periodic duty profile. Evaluation is allocation-free and noexcept.
class InputProfile {
 public:
  /// Validates and takes the knots: at least two, times finite, >= 0, non-decreasing, at most
  /// two knots per time (a step), last time > 0, duties finite and within [-1, 1].
  /// Throws ProfileError naming `name` and the offending knot index.
  static InputProfile FromKnots(std::string name, std::vector<ProfileKnot> knots);

  /// Duty at t_s. The profile repeats with period_s(); before the first knot of a repetition
  /// the first knot's duty holds; at a step the later value applies. Non-finite t_s gives 0.
  [[nodiscard]] Duty At(double t_s) const noexcept;
  /// The same duty, bit for bit, found from `cursor`: the caller's hint where the last lookup
  /// ended (start it at 0; any value is safe). A player reading the profile forward in time
  /// finds its segment in one or two comparisons instead of a search from the start each time;
  /// a jump (back, into another repetition, far ahead) falls back to the search.
  [[nodiscard]] Duty At(double t_s, std::size_t& cursor) const noexcept;
  /// Length of one repetition: the last knot's time.
  [[nodiscard]] double period_s() const noexcept { return knots_.back().time_s; }
  /// Built-in name or the file the profile came from (for messages and reports).
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// The knots, in time order.
  [[nodiscard]] std::span<const ProfileKnot> knots() const noexcept { return knots_; }

 private:
  InputProfile(std::string name, std::vector<ProfileKnot> knots)
      : name_(std::move(name)), knots_(std::move(knots)) {}
  /// Index of the first knot strictly after local_s (upper bound), tried at `hint` and the
  /// segment after it before searching.
  [[nodiscard]] std::size_t KnotAfter(double local_s, std::size_t hint) const noexcept;
  [[nodiscard]] bool IsKnotAfter(double local_s, std::size_t index) const noexcept;
  std::string name_;
  std::vector<ProfileKnot> knots_;
};

/// The names LoadInputProfile accepts besides CSV paths.
[[nodiscard]] std::span<const std::string_view> BuiltinProfileNames() noexcept;

/// The 36 s open-loop test profile: sudden steps and gradual ramps on both wheels, straight
/// driving, turning in place, arcs and reversals, starting and ending at rest.
[[nodiscard]] InputProfile OpenLoopProfile();

/// Parses CSV text with the reader of `hiltwin assess` (analysis::ParseCsv): header
/// `time,left,right`, then one row per knot. A hiltwin log (first column time or time_s, with
/// columns named duty_left and duty_right, e.g. `hiltwin ecs --mode openloop --log`) is read
/// by those two columns and its other columns are ignored, so a logged run replays as a
/// profile. `source_name` is used in messages ("file:line:column: ...", column = CSV field).
/// Throws ProfileError.
[[nodiscard]] InputProfile ParseCsvProfile(std::string_view text, std::string_view source_name);

/// Reads and parses a CSV profile file. Throws ProfileError (also when it cannot be read).
[[nodiscard]] InputProfile LoadCsvProfile(const std::filesystem::path& path);

/// A built-in name (see BuiltinProfileNames) or a path to a CSV file. Throws ProfileError.
[[nodiscard]] InputProfile LoadInputProfile(std::string_view name_or_path);

}  // namespace hiltwin::app
