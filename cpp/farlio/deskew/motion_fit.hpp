#pragma once
// The paper's "linear regression" of the sensor motion during a scan: poses of the sensor at
// several instants tau (s since scan start), taken from the fusion's history, are expressed
// relative to the pose at the scan end, xi_i = log(T_end^-1 T(tau_i)), and each of the six
// components is fitted by least squares with a line xi(tau) = offset + rate * tau.
#include <utility>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/deskew/scan_motion.hpp"

namespace farlio::deskew {

/// Needs at least two samples with distinct tau; otherwise returns the identity motion.
ScanMotion fit_scan_motion(const std::vector<std::pair<double, SE3>>& sensor_poses_at_tau,
                           const SE3& sensor_pose_at_end);

}  // namespace farlio::deskew
