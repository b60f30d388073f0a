#pragma once
// The LiDAR result as EKF measurements (paper eq. 9) with the uncertainty the registration itself
// reports: the body pose as one 6-d group [p_world; roll, pitch, yaw] whose covariance is the
// registration's (registration/degeneracy.hpp) moved into those coordinates, and the eq. (6)
// velocity whose covariance follows from the two poses it is differenced from. Where the scan
// constrains the pose well the LiDAR is trusted accordingly; along a degenerate direction its
// covariance is large and the IMU prediction carries the state.
#include <Eigen/Core>
#include <optional>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"

namespace farlio::fusion {

/// Covariance of z = [p_world; roll, pitch, yaw] of body_pose, from the covariance of a right
/// perturbation [t; r] of it (body frame), with the config's floors added.
Mat6d pose_measurement_covariance(const Mat6d& body_covariance, const SE3& body_pose, const FusionConfig& config);

/// The fixed covariance of the same group from lidar_position_std_m and lidar_*_std_rad (the
/// paper's measurement noise, used when the registration's covariance is not).
Mat6d fixed_pose_covariance(const FusionConfig& config);

/// Covariance of the eq. (6) body velocity (p_k - p_{k-1}) / dt: the translation covariances of
/// both poses (body frame) over dt^2, plus lidar_velocity_std_m_s^2 per axis.
Eigen::Matrix3d velocity_measurement_covariance(const Mat6d& body_covariance, const Mat6d& previous_body_covariance,
                                                double dt_s, const FusionConfig& config);

}  // namespace farlio::fusion
