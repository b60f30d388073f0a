#pragma once
// Analytic test trajectories for the fusion tests: a smooth pose p(t), roll/pitch/yaw(t) with
// exact derivatives, and the exact IMU it produces (gyro = body angular velocity, accel =
// R^T (a_world - g_world)). The rotation and the body rates are computed here independently of
// the code under test (elementary rotations, inverse Euler-rate relation).
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "farlio/core/se3.hpp"
#include "farlio/core/time.hpp"
#include "farlio/core/types.hpp"

namespace farlio::test {

inline constexpr double kGravity_m_s2 = 9.81;
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;

/// A circle of speed speed_m_s and yaw rate yaw_rate_rad_s (heading along the path), with roll,
/// pitch and height oscillating at wobble_hz.
struct TestTrajectory {
  double speed_m_s = 30.0;
  double yaw_rate_rad_s = 1.0;
  double roll_amplitude_rad = 0.05;
  double pitch_amplitude_rad = 0.03;
  double height_amplitude_m = 0.5;
  double wobble_hz = 0.5;

  struct Sample {
    Eigen::Vector3d p, v_world, a_world, rpy, rpy_dot;
  };

  [[nodiscard]] Sample at(double t) const {
    const double w = yaw_rate_rad_s, V = speed_m_s, f = 2.0 * std::numbers::pi * wobble_hz;
    Sample s;
    const double th = w * t;
    s.v_world = {V * std::cos(th), V * std::sin(th), height_amplitude_m * f * std::cos(f * t)};
    s.a_world = {-V * w * std::sin(th), V * w * std::cos(th), -height_amplitude_m * f * f * std::sin(f * t)};
    if (std::abs(w) > 0.0) {
      s.p = {V / w * std::sin(th), V / w * (1.0 - std::cos(th)), height_amplitude_m * std::sin(f * t)};
    } else {
      s.p = {V * t, 0.0, height_amplitude_m * std::sin(f * t)};
    }
    s.rpy = {roll_amplitude_rad * std::sin(f * t), pitch_amplitude_rad * std::sin(f * t + 1.0), th};
    s.rpy_dot = {roll_amplitude_rad * f * std::cos(f * t), pitch_amplitude_rad * f * std::cos(f * t + 1.0), w};
    return s;
  }

  [[nodiscard]] static Eigen::Matrix3d rotation(const Eigen::Vector3d& rpy) {
    return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }

  [[nodiscard]] SE3 pose(double t) const {
    const Sample s = at(t);
    return {rotation(s.rpy), s.p};
  }
  [[nodiscard]] Eigen::Vector3d rpy(double t) const { return at(t).rpy; }
  [[nodiscard]] Eigen::Vector3d velocity_body(double t) const {
    const Sample s = at(t);
    return rotation(s.rpy).transpose() * s.v_world;
  }
  [[nodiscard]] Eigen::Vector3d angular_velocity_body(double t) const {
    const Sample s = at(t);
    const double sr = std::sin(s.rpy.x()), cr = std::cos(s.rpy.x());
    const double sp = std::sin(s.rpy.y()), cp = std::cos(s.rpy.y());
    const Eigen::Vector3d& d = s.rpy_dot;
    return {d.x() - d.z() * sp, d.y() * cr + d.z() * sr * cp, -d.y() * sr + d.z() * cr * cp};
  }
  [[nodiscard]] ImuSample imu(double t) const {
    const Sample s = at(t);
    ImuSample m;
    m.stamp_ns = seconds_to_ns(t);
    m.gyro_rad_s = angular_velocity_body(t);
    m.accel_m_s2 = rotation(s.rpy).transpose() * (s.a_world - Eigen::Vector3d(0.0, 0.0, -kGravity_m_s2));
    return m;
  }
};

/// Position error in m and rotation error in degrees of an estimate against the truth.
inline double position_error_m(const SE3& est, const SE3& truth) {
  return (est.translation() - truth.translation()).norm();
}
inline double rotation_error_deg(const SE3& est, const SE3& truth) {
  return (truth.inverse() * est).angle_rad() * kDegPerRad;
}

}  // namespace farlio::test
