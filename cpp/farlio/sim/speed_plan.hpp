#pragma once
// The speed along a Path over time: a C2 speed curve v(t) (smoothstep ramps between plateaus)
// planned so that every corner is driven at a speed whose lateral acceleration v^2 * kappa
// stays within the limit, with optional full stops before chosen corners. Arc length s(t) is
// the exact integral of v(t). Open paths start at rest. Closed paths repeat a steady lap that
// starts and ends on a plateau at full speed, so the repetition is C2 too; the first lap is
// either that steady lap (a flying start) or, with a standing start, a lap from rest that
// accelerates out of the start and ends at the steady lap's start speed, again C2 (every speed
// knot has zero first and second derivatives).
#include <cstddef>
#include <utility>
#include <vector>

#include "farlio/sim/path.hpp"
#include "farlio/sim/smooth_curve.hpp"

namespace farlio::sim {

struct SpeedLimits {
  double max_speed_m_s = 0.0;
  double max_lateral_accel_m_s2 = 0.0;
  /// Peak longitudinal acceleration/braking of a speed ramp.
  double max_longitudinal_accel_m_s2 = 0.0;
  /// Open paths, and closed ones with a standing start, start at rest and wait this long
  /// before moving.
  double initial_rest_s = 0.0;
  /// Closed paths only: the first lap starts from rest (a standing start) instead of at full
  /// speed (a flying start). Open paths always start from rest.
  bool standing_start = false;
};

/// A full stop of hold_s seconds just before the corner with index before_corner.
struct Stop {
  std::size_t before_corner = 0;
  double hold_s = 0.0;
};

/// Arc length, speed and tangential acceleration at one instant.
struct Progress {
  double s_m = 0.0;
  double v_m_s = 0.0;
  double a_m_s2 = 0.0;
};

class SpeedPlan {
 public:
  SpeedPlan() = default;
  /// Throws std::invalid_argument when the path leaves no room to brake for a corner.
  SpeedPlan(const Path& path, const SpeedLimits& limits, const std::vector<Stop>& stops);

  /// Progress at time t_s (t = 0 is the start; before it the start state extends: at rest,
  /// or cruising at the start speed for a flying start).
  [[nodiscard]] Progress at(double t_s) const;
  /// Time intervals [begin, end] during which the vehicle stands still for a Stop (not the
  /// initial rest), within [0, plan_duration_s()].
  [[nodiscard]] const std::vector<std::pair<double, double>>& stop_intervals_s() const { return stops_s_; }
  /// Time from t = 0 until the end of the path is first reached: the path end (open paths,
  /// including the initial rest; the vehicle then goes on straight at full speed) or the end of
  /// the first lap (closed paths: including the initial rest and the acceleration of a standing
  /// start; equal to lap_time_s() for a flying start).
  [[nodiscard]] double plan_duration_s() const { return plan_duration_s_; }
  /// Closed paths: time of one steady lap, start line to start line at full speed (every lap
  /// after the first); 0 for open paths.
  [[nodiscard]] double lap_time_s() const { return lap_time_s_; }

 private:
  SmoothCurve first_;  ///< v over t on [0, plan_duration_s_]: the open path or the first lap
  SmoothCurve lap_;    ///< v over t on [0, lap_time_s_]: the steady lap of a closed path
  std::vector<std::pair<double, double>> stops_s_;
  double plan_duration_s_ = 0.0;
  double lap_time_s_ = 0.0;
  double lap_length_m_ = 0.0;
  bool periodic_ = false;
};

}  // namespace farlio::sim
