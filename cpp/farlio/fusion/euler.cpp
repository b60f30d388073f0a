#include "farlio/fusion/euler.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace farlio::fusion {

Eigen::Matrix3d rotation_from_euler(const Eigen::Vector3d& rpy_rad) {
  const double cr = std::cos(rpy_rad.x()), sr = std::sin(rpy_rad.x());
  const double cp = std::cos(rpy_rad.y()), sp = std::sin(rpy_rad.y());
  const double cy = std::cos(rpy_rad.z()), sy = std::sin(rpy_rad.z());
  Eigen::Matrix3d R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return R;
}

Eigen::Vector3d euler_from_rotation(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
}

double wrap_angle(double angle_rad) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double a = std::remainder(angle_rad, kTwoPi);  // in [-pi, pi]
  if (a <= -std::numbers::pi) a += kTwoPi;
  return a;
}

}  // namespace farlio::fusion
