#pragma once
// Euler angles roll/pitch/yaw in the ZYX convention: R = Rz(yaw) * Ry(pitch) * Rx(roll).
#include <Eigen/Core>

namespace farlio::fusion {

/// Rotation matrix (body -> world) of [roll, pitch, yaw] in radians.
Eigen::Matrix3d rotation_from_euler(const Eigen::Vector3d& rpy_rad);
/// [roll, pitch, yaw] of a rotation matrix; pitch in [-pi/2, pi/2], roll and yaw in (-pi, pi].
Eigen::Vector3d euler_from_rotation(const Eigen::Matrix3d& R);
/// The angle wrapped into (-pi, pi].
double wrap_angle(double angle_rad);

}  // namespace farlio::fusion
