#pragma once
// The speed along a Path over time: a C2 speed curve v(t) (smoothstep ramps between plateaus)
// planned so that every corner is driven at a speed whose lateral acceleration v^2 * kappa
// stays within the limit, with optional full stops before chosen corners. Arc length s(t) is
// the exact integral of v(t). Closed paths repeat lap after lap (the plan starts and ends on a
// plateau at the same speed, so the repetition is C2 too).
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
  /// Open paths start at rest and wait this long before moving.
  double initial_rest_s = 0.0;
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

  [[nodiscard]] Progress at(double t_s) const;
  /// Time intervals [begin, end] during which the vehicle stands still (stops only).
  [[nodiscard]] const std::vector<std::pair<double, double>>& stop_intervals_s() const { return stops_s_; }
  /// Time of one lap (closed paths) or until the path end is reached (open paths).
  [[nodiscard]] double plan_duration_s() const { return plan_duration_s_; }

 private:
  SmoothCurve speed_;  ///< v over t
  std::vector<std::pair<double, double>> stops_s_;
  double plan_duration_s_ = 0.0;
  double lap_length_m_ = 0.0;
  bool periodic_ = false;
};

}  // namespace farlio::sim
