#pragma once
// Registration of one cloud onto another with the same machinery as the odometry: the target
// becomes a voxel map (with covariances), the source is downsampled to the map spacing and gets
// covariances from its own frame map, then sparsity-aware GICP runs from the initial guess.
#include <Eigen/Core>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/registration/gicp.hpp"

namespace farlio::pipeline {

/// T_target_source starting from `initial_guess`; the correspondence threshold is
/// config.threshold.initial_threshold_m (sigma: 3 sigma distance, sigma / 3 kernel scale).
registration::RegistrationResult register_pair(const std::vector<Eigen::Vector3f>& source,
                                               const std::vector<Eigen::Vector3f>& target, const SE3& initial_guess,
                                               const Config& config = Config());

}  // namespace farlio::pipeline
