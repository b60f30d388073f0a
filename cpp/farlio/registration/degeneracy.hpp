#pragma once
// How well a registration constrains the pose, from its Gauss-Newton H: the pose covariance
// covariance_scale * H^-1 moved into the body (IMU) frame, and per block (translation, rotation)
// the marginal std along each principal direction. A direction whose std exceeds the
// registration's degenerate_* threshold is degenerate: the scene does not fix the pose along it
// (a tunnel along its axis, a plane's in-plane directions). The fusion then takes that direction
// from the IMU prior (docs/fusion.md, "Degeneracy").
#include <Eigen/Core>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/registration/linear_system.hpp"

namespace farlio::registration {

/// The pose information [translation; rotation] of a right perturbation of the body pose, in
/// physical units (1/m^2, 1/rad^2): H of a right perturbation of the sensor pose (normalised
/// units) moved through T_body_sensor and divided by covariance_scale.
Mat6d body_information(const Mat6d& H_sensor, const SE3& T_body_sensor, double covariance_scale);

/// Its inverse, with directions the information does not constrain at all capped at
/// kUnconstrainedStd (a finite covariance the fusion can still use).
Mat6d covariance_from_information(const Mat6d& information);
inline constexpr double kUnconstrainedStd = 1e3;  ///< m or rad

struct Degeneracy {
  /// Marginal std along the principal directions, largest first (m, rad), and those directions
  /// (columns, body frame).
  Eigen::Vector3d translation_std_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d translation_axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rotation_std_rad = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation_axes = Eigen::Matrix3d::Identity();
  int degenerate_translations = 0;  ///< directions over the threshold
  int degenerate_rotations = 0;
  [[nodiscard]] bool degenerate() const { return degenerate_translations + degenerate_rotations > 0; }
};

/// The principal stds of the marginal covariance blocks of `covariance` ([t; r], any frame: the
/// axes are in the covariance's frame). `inliers`: the correspondences of the system the
/// covariance comes from (the per-point std of degenerate_translation_point_std_m).
Degeneracy analyze_degeneracy(const Mat6d& covariance, double inliers, const RegistrationConfig& config);

/// The directions of `d` over their thresholds as unit columns of a 6 x m matrix ([t; r]).
Eigen::Matrix<double, 6, Eigen::Dynamic> degenerate_directions(const Degeneracy& d);

/// The Gauss-Newton step: minimises |H dx + b| over the steps with no component along the
/// degenerate directions of `d` (solution remapping: the pose stays at its initial guess along
/// them). Without degenerate directions, the plain solve of H dx = -b.
Vec6d step_without_degenerate_directions(const Mat6d& H, const Vec6d& b, const Degeneracy& d);

/// `covariance` with the degenerate directions of `d` released: variance kUnconstrainedStd^2 added
/// along each, so that a filter takes the state there from its own prediction.
Mat6d release_degenerate_directions(const Mat6d& covariance, const Degeneracy& d);

/// The same for the degenerate rotation axes only.
Mat6d release_degenerate_rotations(const Mat6d& covariance, const Degeneracy& d);

/// What the scan says along its degenerate translation directions: the Gauss-Newton step of the
/// unconstrained system (H + damping I) dx = -b (sensor frame, right perturbation, the system a
/// registration held those directions in) moved into the body frame through T_body_sensor and
/// projected on the degenerate translation axes of `d` (body frame). Zero without degenerate
/// translations. The body pose the scan measures is body_pose * exp([step; 0]).
Eigen::Vector3d degenerate_translation_step(const LinearSystem& system, double damping, const SE3& T_body_sensor,
                                            const Degeneracy& d);

}  // namespace farlio::registration
