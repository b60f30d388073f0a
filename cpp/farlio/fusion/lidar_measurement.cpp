#include "farlio/fusion/lidar_measurement.hpp"

#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/kinematic_model.hpp"

namespace farlio::fusion {
namespace {
double square(double v) { return v * v; }
}  // namespace

Mat6d pose_measurement_covariance(const Mat6d& body_covariance, const SE3& body_pose, const FusionConfig& config) {
  // p_world = p + R t and angles(R exp(r)) = angles(R) + E(angles) r to first order
  Mat6d J = Mat6d::Zero();
  J.topLeftCorner<3, 3>() = body_pose.rotation();
  J.bottomRightCorner<3, 3>() = euler_rate_matrix(euler_from_rotation(body_pose.rotation()));
  Mat6d R = J * body_covariance * J.transpose();
  R.diagonal().head<3>().array() += square(config.lidar_min_position_std_m);
  R.diagonal().tail<3>().array() += square(config.lidar_min_attitude_std_rad);
  return 0.5 * (R + R.transpose());
}

Mat6d fixed_pose_covariance(const FusionConfig& config) {
  Vec6d d;
  d << Eigen::Vector3d::Constant(square(config.lidar_position_std_m)), square(config.lidar_roll_pitch_std_rad),
      square(config.lidar_roll_pitch_std_rad), square(config.lidar_yaw_std_rad);
  return d.asDiagonal();
}

Eigen::Matrix3d velocity_measurement_covariance(const Mat6d& body_covariance, const Mat6d& previous_body_covariance,
                                                double dt_s, const FusionConfig& config) {
  Eigen::Matrix3d C =
      (body_covariance.topLeftCorner<3, 3>() + previous_body_covariance.topLeftCorner<3, 3>()) / square(dt_s);
  C.diagonal().array() += square(config.lidar_velocity_std_m_s);
  return 0.5 * (C + C.transpose());
}

}  // namespace farlio::fusion
