#include "farlio/fusion/measurement_model.hpp"

#include "farlio/fusion/euler.hpp"

namespace farlio::fusion {

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
  const MeasurementSlot s = slot_of(kind);
  return x.segment(s.first_state_index, s.dim);
}

Eigen::VectorXd measurement_difference(MeasurementKind kind, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd d = a - b;
  for (Eigen::Index i = slot_of(kind).first_angle; i < d.size(); ++i) d(i) = wrap_angle(d(i));
  return d;
}

Eigen::MatrixXd measurement_jacobian(MeasurementKind kind) {
  const MeasurementSlot s = slot_of(kind);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(s.dim, kStateDim);
  H.block(0, s.first_state_index, s.dim, s.dim).setIdentity();
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
