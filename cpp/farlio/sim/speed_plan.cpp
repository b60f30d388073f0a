#include "farlio/sim/speed_plan.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace farlio::sim {
namespace {
/// Peak slope of the quintic smoothstep: a ramp of dv over tau peaks at 15/8 * dv / tau.
constexpr double kSmoothstepPeakSlope = 1.875;
constexpr double kMinKnotSpacing_s = 1e-9;
constexpr double kRoomTolerance_m = 1e-6;
constexpr int kBisectionSteps = 60;

/// Builds the speed knots while tracking time, arc length and speed.
class Planner {
 public:
  Planner(double v0, double a_lon) : v_(v0), a_lon_(a_lon) { curve_.add_knot(0.0, v0); }

  [[nodiscard]] double ramp_time_s(double v0, double v1) const {
    return kSmoothstepPeakSlope * std::abs(v1 - v0) / a_lon_;
  }
  [[nodiscard]] double ramp_distance_m(double v0, double v1) const { return 0.5 * (v0 + v1) * ramp_time_s(v0, v1); }

  void ramp_to(double v1) {
    const double tau = ramp_time_s(v_, v1);
    if (tau < kMinKnotSpacing_s) return;
    s_ += 0.5 * (v_ + v1) * tau;
    t_ += tau;
    v_ = v1;
    curve_.add_knot(t_, v_);
  }
  void hold(double dt_s) {
    t_ += dt_s;
    curve_.add_knot(t_, v_);
  }
  void cruise_to(double s_m) {
    if (v_ <= 0.0) throw std::logic_error("SpeedPlan: cannot cruise at zero speed");
    const double dt = (s_m - s_) / v_;
    if (dt < kMinKnotSpacing_s) return;
    hold(dt);
    s_ = s_m;
  }
  /// Cruise at the fastest speed (<= v_max) that still allows reaching v_end exactly at s_end.
  void arrive(double s_end_m, double v_end, double v_max, const std::string& what) {
    const double room = s_end_m - s_;
    if (v_ <= v_end && ramp_distance_m(v_, v_end) >= room) {  // accelerating: may run on past s_end
      ramp_to(v_end);
      return;
    }
    if (ramp_distance_m(v_, v_end) > room + kRoomTolerance_m)
      throw std::invalid_argument("SpeedPlan: no room to slow down for " + what);
    const auto need = [&](double v) { return ramp_distance_m(v_, v) + ramp_distance_m(v, v_end); };
    double lo = std::max(v_, v_end), hi = std::max(lo, v_max);
    double v_cruise = hi;
    if (need(hi) > room) {
      for (int i = 0; i < kBisectionSteps; ++i) {
        const double mid = 0.5 * (lo + hi);
        (need(mid) <= room ? lo : hi) = mid;
      }
      v_cruise = lo;
    }
    ramp_to(v_cruise);
    cruise_to(s_end_m - ramp_distance_m(v_cruise, v_end));
    ramp_to(v_end);
  }

  double t_ = 0.0, s_ = 0.0, v_;
  double a_lon_;
  SmoothCurve curve_;
};

/// Drives every corner of the path once from the planner's state (at s = 0), recording the
/// stops' time intervals.
void drive_corners(Planner& plan, const Path& path, const SpeedLimits& limits, const std::vector<Stop>& stops,
                   std::vector<std::pair<double, double>>& stop_intervals_s) {
  const auto& corners = path.corners();
  for (std::size_t c = 0; c < corners.size(); ++c) {
    const double v_corner =
        std::min(limits.max_speed_m_s, std::sqrt(limits.max_lateral_accel_m_s2 / corners[c].peak_curvature_1_m));
    const auto stop = std::find_if(stops.begin(), stops.end(), [c](const Stop& st) { return st.before_corner == c; });
    const std::string what = "corner " + std::to_string(c);
    plan.arrive(corners[c].s_begin_m, stop != stops.end() ? 0.0 : v_corner, limits.max_speed_m_s, what);
    if (stop != stops.end()) {
      const double begin = plan.t_;
      plan.hold(stop->hold_s);
      stop_intervals_s.emplace_back(begin, plan.t_);
    }
    if (plan.v_ < v_corner) plan.ramp_to(v_corner);
    if (plan.s_ < corners[c].s_end_m) plan.cruise_to(corners[c].s_end_m);
  }
}

/// Ends a lap of a closed path exactly at the start line at speed v_end.
void finish_lap(Planner& plan, double lap_length_m, double v_end, double v_max) {
  plan.arrive(lap_length_m, v_end, v_max, "the lap end");
  if (std::abs(plan.s_ - lap_length_m) > kRoomTolerance_m || plan.v_ != v_end)
    throw std::invalid_argument("SpeedPlan: lap does not end at its start speed");
}
}  // namespace

SpeedPlan::SpeedPlan(const Path& path, const SpeedLimits& limits, const std::vector<Stop>& stops) {
  periodic_ = path.closed();
  lap_length_m_ = path.length_m();
  const double a_lon = limits.max_longitudinal_accel_m_s2;
  // A steady lap starts and ends on a plateau at full speed.
  const double v_lap = limits.max_speed_m_s;
  std::vector<std::pair<double, double>> lap_stops_s;
  if (periodic_) {
    Planner lap(v_lap, a_lon);
    drive_corners(lap, path, limits, stops, lap_stops_s);
    finish_lap(lap, lap_length_m_, v_lap, limits.max_speed_m_s);
    lap_time_s_ = lap.t_;
    lap_ = std::move(lap.curve_);
  }
  if (periodic_ && !limits.standing_start) {  // flying start: the first lap is a steady one
    first_ = lap_;
    plan_duration_s_ = lap_time_s_;
    stops_s_ = std::move(lap_stops_s);
    return;
  }
  Planner plan(0.0, a_lon);
  if (limits.initial_rest_s > 0.0) plan.hold(limits.initial_rest_s);
  drive_corners(plan, path, limits, stops, stops_s_);
  if (periodic_) {
    finish_lap(plan, lap_length_m_, v_lap, limits.max_speed_m_s);  // hands over to the steady lap
  } else {
    plan.ramp_to(limits.max_speed_m_s);
    if (plan.s_ < lap_length_m_) plan.cruise_to(lap_length_m_);
  }
  plan_duration_s_ = plan.t_;
  first_ = std::move(plan.curve_);
}

Progress SpeedPlan::at(double t_s) const {
  if (!periodic_ || t_s < plan_duration_s_) return {first_.integral(t_s), first_.value(t_s), first_.derivative(t_s)};
  // After the first lap: steady laps, each starting at the start line.
  t_s -= plan_duration_s_;
  const double laps = std::floor(t_s / lap_time_s_);
  t_s -= laps * lap_time_s_;
  return {(laps + 1.0) * lap_length_m_ + lap_.integral(t_s), lap_.value(t_s), lap_.derivative(t_s)};
}

}  // namespace farlio::sim
