#pragma once
// The measurement models h(x) of the EKF (paper eq. 9): the LiDAR groups observe a contiguous
// block of the state (linear selectors); the reference angles observe roll and pitch against
// gravity, i.e. of the attitude turned into the level frame by the world frame's tilt (the
// selector of roll and pitch while the tilt is zero). Angles have wrapped residuals.
#include <Eigen/Core>

#include "farlio/fusion/kinematic_model.hpp"

namespace farlio::fusion {

enum class MeasurementKind {
  kPosition,     ///< p_world (3), m
  kOrientation,  ///< roll, pitch, yaw (3), rad
  kVelocity,     ///< v_body (3), m/s
  kRollPitch,    ///< roll, pitch (2) against gravity, rad: the reference angles
  kPose,         ///< p_world (3) and roll, pitch, yaw (3) with one joint covariance
};

struct MeasurementSlot {
  int first_state_index = 0;
  int dim = 0;
  int first_angle = 0;  ///< entries [first_angle, dim) are angles (wrapped); dim: none
};

MeasurementSlot slot_of(MeasurementKind kind);
/// h(x) for the group.
Eigen::VectorXd measure(MeasurementKind kind, const StateVector& x);
/// a - b for two values of the group (angles wrapped into (-pi, pi]).
Eigen::VectorXd measurement_difference(MeasurementKind kind, const Eigen::VectorXd& a, const Eigen::VectorXd& b);
/// H = dh/dx at x: the selector matrix of the group, or (reference angles) its derivative.
Eigen::MatrixXd measurement_jacobian(MeasurementKind kind, const StateVector& x);
const char* kind_name(MeasurementKind kind);

}  // namespace farlio::fusion
