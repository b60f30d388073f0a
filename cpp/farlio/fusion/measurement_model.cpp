#include "farlio/fusion/measurement_model.hpp"

#include <vector>

#include "farlio/fusion/euler.hpp"

namespace farlio::fusion {
namespace {

/// Roll and pitch against gravity: of the attitude in the level frame.
Eigen::Vector2d level_roll_pitch(const StateVector& x) {
  const Eigen::Matrix3d R = level_from_world(x) * rotation_from_euler(x.segment<3>(kAttitudeIndex));
  return euler_from_rotation(R).head<2>();
}

/// Step of the central differences of the reference angles' Jacobian (rad).
constexpr double kAngleStep_rad = 1e-6;

}  // namespace

MeasurementSlot slot_of(MeasurementKind kind) {
  switch (kind) {
    case MeasurementKind::kPosition: return {kPositionIndex, 3, 3};
    case MeasurementKind::kOrientation: return {kAttitudeIndex, 3, 0};
    case MeasurementKind::kVelocity: return {kVelocityIndex, 3, 3};
    case MeasurementKind::kRollPitch: return {kAttitudeIndex, 2, 0};
    case MeasurementKind::kPose: return {kPositionIndex, 6, kAttitudeIndex - kPositionIndex};
  }
  return {};
}

Eigen::VectorXd measure(MeasurementKind kind, const StateVector& x) {
  if (kind == MeasurementKind::kRollPitch && !x.segment<2>(kTiltIndex).isZero(0.0)) return level_roll_pitch(x);
  const MeasurementSlot s = slot_of(kind);
  return x.segment(s.first_state_index, s.dim);
}

Eigen::VectorXd measurement_difference(MeasurementKind kind, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd d = a - b;
  for (Eigen::Index i = slot_of(kind).first_angle; i < d.size(); ++i) d(i) = wrap_angle(d(i));
  return d;
}

Eigen::MatrixXd measurement_jacobian(MeasurementKind kind, const StateVector& x) {
  const MeasurementSlot s = slot_of(kind);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(s.dim, kStateDim);
  H.block(0, s.first_state_index, s.dim, s.dim).setIdentity();
  if (kind != MeasurementKind::kRollPitch) return H;
  // the reference angles: central differences over the tilt, and over the attitude unless the
  // tilt is zero (then h is the selector of roll and pitch)
  std::vector<int> columns{kTiltIndex, kTiltIndex + 1};
  if (!x.segment<2>(kTiltIndex).isZero(0.0))
    columns.insert(columns.end(), {kAttitudeIndex, kAttitudeIndex + 1, kAttitudeIndex + 2});
  for (const int i : columns) {
    StateVector plus = x, minus = x;
    plus(i) += kAngleStep_rad;
    minus(i) -= kAngleStep_rad;
    H.col(i) = measurement_difference(kind, level_roll_pitch(plus), level_roll_pitch(minus)) / (2.0 * kAngleStep_rad);
  }
  return H;
}

const char* kind_name(MeasurementKind kind) {
  switch (kind) {
    case MeasurementKind::kPosition: return "position";
    case MeasurementKind::kOrientation: return "orientation";
    case MeasurementKind::kVelocity: return "velocity";
    case MeasurementKind::kRollPitch: return "roll/pitch reference";
    case MeasurementKind::kPose: return "pose";
  }
  return "unknown";
}

}  // namespace farlio::fusion
