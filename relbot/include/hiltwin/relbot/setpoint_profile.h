#pragma once
/// Wheel position setpoints for the ECS's closed loop (thesis §7.2, appendix E): the built-in
/// `closedloop` profile and user CSV files `time,left_m,right_m`. A setpoint profile is a
/// signal of knots joined by straight lines or by smooth rest-to-rest moves; a repeated time
/// marks a sudden step. Unlike a duty profile it does not repeat: after its last knot it holds
/// the last position (a robot told to stop there), and its length (the last knot's time) is
/// the natural duration of a run. Evaluation is noexcept and allocation-free.

#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/relbot/input_profile.h"  // ProfileError

namespace hiltwin::app {

/// Wheel travel of both wheels, in metres from where the run started.
struct WheelPositions {
  double left_m = 0.0;
  double right_m = 0.0;
};

/// How the segment from one knot to the next is drawn.
enum class SegmentShape : std::uint8_t {
  kLinear,  ///< straight line: constant speed (CSV files)
  /// Cycloidal rest-to-rest move: p = a + (b - a)·(s - sin(2πs)/(2π)), s in [0, 1]. Speed
  /// 1 - cos(2πs) and acceleration sin(2πs) both start and end at zero, so the acceleration
  /// is continuous (no jolt at start or stop); peak speed 2·Δ/T, peak acceleration 2π·Δ/T².
  kSmooth,
};

/// One corner of a setpoint profile.
struct SetpointKnot {
  double time_s = 0.0;                         ///< time since the start of the run
  WheelPositions position;                     ///< setpoint at time_s (right-continuous at steps)
  SegmentShape shape = SegmentShape::kLinear;  ///< shape of the segment that starts here
};

/// A piecewise setpoint signal. Evaluation is allocation-free and noexcept.
class SetpointProfile {
 public:
  /// Validates and takes the knots: at least two, times finite, >= 0, non-decreasing, at most
  /// two knots per time (a step), last time > 0, positions finite. Throws ProfileError naming
  /// `name` and the offending knot index.
  static SetpointProfile FromKnots(std::string name, std::vector<SetpointKnot> knots);

  /// Setpoint at t_s: before the first knot the first position holds, after the last knot the
  /// last position holds (no repetition), at a step the later value applies. Non-finite t_s
  /// gives the first position.
  [[nodiscard]] WheelPositions At(double t_s) const noexcept;
  /// The last knot's time: when the profile has reached its final setpoint.
  [[nodiscard]] double length_s() const noexcept { return knots_.back().time_s; }
  /// Built-in name or the file the profile came from.
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] std::span<const SetpointKnot> knots() const noexcept { return knots_; }

 private:
  SetpointProfile(std::string name, std::vector<SetpointKnot> knots)
      : name_(std::move(name)), knots_(std::move(knots)) {}
  std::string name_;
  std::vector<SetpointKnot> knots_;
};

/// The built-in `closedloop` profile (thesis §7.2: "the 2.5 m test", error below 3 mm). The
/// thesis gives no formula; ours: both wheels rest, make one cycloidal (smooth) move of
/// kClosedLoopDistanceM forward, and rest again so the controller settles. Peak speed
/// 2·2.5/8 = 0.625 m/s (duty about 0.65 of the RELbot's 0.96 m/s top speed), peak
/// acceleration 2π·2.5/64 = 0.245 m/s².
inline constexpr double kClosedLoopRestS = 1.0;
inline constexpr double kClosedLoopMoveS = 8.0;
inline constexpr double kClosedLoopSettleS = 3.0;
inline constexpr double kClosedLoopDistanceM = 2.5;
[[nodiscard]] SetpointProfile ClosedLoopProfile();

/// The names LoadSetpointProfile accepts besides CSV paths.
[[nodiscard]] std::span<const std::string_view> BuiltinSetpointNames() noexcept;

/// Parses CSV text with the reader of input profiles (analysis::ParseCsv): header
/// `time,left_m,right_m` (or `time_s,...`), then one row per knot, straight lines between
/// knots, a repeated time for a step. Throws ProfileError with "file:line:column: ...".
[[nodiscard]] SetpointProfile ParseCsvSetpoints(std::string_view text,
                                                std::string_view source_name);

/// Reads and parses a CSV setpoint file. Throws ProfileError (also when it cannot be read).
[[nodiscard]] SetpointProfile LoadCsvSetpoints(const std::filesystem::path& path);

/// A built-in name (see BuiltinSetpointNames) or a path to a CSV file. Throws ProfileError.
[[nodiscard]] SetpointProfile LoadSetpointProfile(std::string_view name_or_path);

}  // namespace hiltwin::app
