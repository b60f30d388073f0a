#include "farlio/sim/motion.hpp"

#include <cmath>
#include <numbers>

namespace farlio::sim {

Mat3d euler_zyx_rotation(const EulerZyx& e) {
  return (Eigen::AngleAxisd(e.yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(e.pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(e.roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d euler_zyx_body_rate(const EulerZyx& e) {
  const double sp = std::sin(e.pitch_rad), cp = std::cos(e.pitch_rad);
  const double sr = std::sin(e.roll_rad), cr = std::cos(e.roll_rad);
  return {e.roll_rate_rad_s - e.yaw_rate_rad_s * sp, e.pitch_rate_rad_s * cr + e.yaw_rate_rad_s * cp * sr,
          -e.pitch_rate_rad_s * sr + e.yaw_rate_rad_s * cp * cr};
}

VehicleMotion::VehicleMotion(Path path, SpeedPlan plan, SmoothCurve road_height_m, double body_height_m,
                             RoadHeightOf height_of)
    : path_(std::move(path)),
      plan_(std::move(plan)),
      road_(std::move(road_height_m)),
      body_height_m_(body_height_m),
      height_of_(height_of) {}

BodyState VehicleMotion::state(double t_s) const {
  const Progress pr = plan_.at(t_s);
  const PathPoint pp = path_.at(pr.s_m);
  // Road height z(s) and its derivatives along the (horizontal) arc length: z = road(s), or
  // z = road(x(s)) by the chain rule.
  const double x = pp.position_m.x();
  double z = 0.0, dz_ds = 0.0, d2z_ds2 = 0.0;
  if (height_of_ == RoadHeightOf::ArcLength) {
    z = road_.value(pr.s_m);
    dz_ds = road_.derivative(pr.s_m);
    d2z_ds2 = road_.second_derivative(pr.s_m);
  } else {
    const double dx_ds = pp.tangent.x(), d2x_ds2 = pp.curvature_1_m * pp.normal.x();
    z = road_.value(x);
    dz_ds = road_.derivative(x) * dx_ds;
    d2z_ds2 = road_.second_derivative(x) * dx_ds * dx_ds + road_.derivative(x) * d2x_ds2;
  }

  const Eigen::Vector3d d1(pp.tangent.x(), pp.tangent.y(), dz_ds);  // dp/ds
  const Eigen::Vector3d d2(pp.curvature_1_m * pp.normal.x(), pp.curvature_1_m * pp.normal.y(), d2z_ds2);
  BodyState st;
  st.velocity_world_m_s = pr.v_m_s * d1;
  st.acceleration_world_m_s2 = pr.a_m_s2 * d1 + pr.v_m_s * pr.v_m_s * d2;

  EulerZyx e;
  e.yaw_rad = pp.heading_rad;
  e.yaw_rate_rad_s = pp.curvature_1_m * pr.v_m_s;
  e.pitch_rad = -std::atan(dz_ds);
  e.pitch_rate_rad_s = -d2z_ds2 * pr.v_m_s / (1.0 + dz_ds * dz_ds);
  st.angular_velocity_body_rad_s = euler_zyx_body_rate(e);
  st.pose_world_body = SE3(euler_zyx_rotation(e), Eigen::Vector3d(x, pp.position_m.y(), z + body_height_m_));
  return st;
}

WalkerMotion::WalkerMotion(Path path, SpeedPlan plan, SmoothCurve yaw_offset_of_t_rad, WalkStyle style)
    : path_(std::move(path)), plan_(std::move(plan)), yaw_offset_(std::move(yaw_offset_of_t_rad)), style_(style) {}

BodyState WalkerMotion::state(double t_s) const {
  const Progress pr = plan_.at(t_s);
  const PathPoint pp = path_.at(pr.s_m);
  const double w = 2.0 * std::numbers::pi / style_.stride_m;  // bob phase per metre
  const double phase = w * pr.s_m;
  // d/dt of f(phase(s(t))) = f' * w * v; second derivative f'' * (w v)^2 + f' * w * a.
  const double wv = w * pr.v_m_s, wa = w * pr.a_m_s2;

  BodyState st;
  const double z = style_.eye_height_m + style_.bob_amplitude_m * std::sin(phase);
  const double dz = style_.bob_amplitude_m * std::cos(phase) * wv;
  const double d2z =
      -style_.bob_amplitude_m * std::sin(phase) * wv * wv + style_.bob_amplitude_m * std::cos(phase) * wa;
  const Eigen::Vector3d t3(pp.tangent.x(), pp.tangent.y(), 0.0), n3(pp.normal.x(), pp.normal.y(), 0.0);
  st.velocity_world_m_s = pr.v_m_s * t3 + Eigen::Vector3d(0, 0, dz);
  st.acceleration_world_m_s2 =
      pr.a_m_s2 * t3 + pr.v_m_s * pr.v_m_s * pp.curvature_1_m * n3 + Eigen::Vector3d(0, 0, d2z);

  EulerZyx e;
  e.yaw_rad = pp.heading_rad + yaw_offset_.value(t_s);
  e.yaw_rate_rad_s = pp.curvature_1_m * pr.v_m_s + yaw_offset_.derivative(t_s);
  e.pitch_rad = style_.pitch_sway_rad * std::sin(phase);
  e.pitch_rate_rad_s = style_.pitch_sway_rad * std::cos(phase) * wv;
  e.roll_rad = style_.roll_sway_rad * std::sin(0.5 * phase);
  e.roll_rate_rad_s = style_.roll_sway_rad * std::cos(0.5 * phase) * 0.5 * wv;
  st.angular_velocity_body_rad_s = euler_zyx_body_rate(e);
  st.pose_world_body = SE3(euler_zyx_rotation(e), Eigen::Vector3d(pp.position_m.x(), pp.position_m.y(), z));
  return st;
}

}  // namespace farlio::sim
