#include "farlio/fusion/kinematic_ekf.hpp"

#include <Eigen/Cholesky>

namespace farlio::fusion {

KinematicEkf::KinematicEkf(double gravity_m_s2, const InputVector& input_variance,
                           const InputVector& bias_walk_variance)
    : gravity_m_s2_(gravity_m_s2), Q_(input_variance.asDiagonal()) {
  bias_walk_.segment<3>(kGyroBiasIndex) = bias_walk_variance.segment<3>(kGyroIndex);
  bias_walk_.segment<3>(kAccelBiasIndex) = bias_walk_variance.segment<3>(kAccelIndex);
}

void KinematicEkf::initialize(const StateVector& x, const StateMatrix& P) {
  x_ = normalized_state(x);
  P_ = P;
  initialized_ = true;
}

void KinematicEkf::predict(const InputVector& u_start, const InputVector& u_mid, const InputVector& u_end,
                           double dt_s) {
  // Jacobians at the step start (the linearisation point of the reference as well).
  const ModelJacobians J = model_jacobians(x_, u_start, gravity_m_s2_);
  const StateMatrix A = StateMatrix::Identity() + dt_s * J.df_dx;
  const InputMatrix B = dt_s * J.df_du;
  x_ = integrate_step(x_, u_start, u_mid, u_end, dt_s, gravity_m_s2_);
  P_ = A * P_ * A.transpose() + B * Q_ * B.transpose();
  P_.diagonal() += dt_s * bias_walk_;
  P_ = 0.5 * (P_ + P_.transpose());
}

double KinematicEkf::mahalanobis_squared(MeasurementKind kind, const Eigen::VectorXd& residual,
                                         const Eigen::MatrixXd& R) const {
  const Eigen::MatrixXd H = measurement_jacobian(kind, x_);
  const Eigen::MatrixXd S = H * P_ * H.transpose() + R;
  return residual.dot(S.ldlt().solve(residual));
}

bool KinematicEkf::update(MeasurementKind kind, const Eigen::VectorXd& residual, const Eigen::MatrixXd& R,
                          double gate_chi2) {
  if (!residual.allFinite()) return false;
  const Eigen::MatrixXd H = measurement_jacobian(kind, x_);
  const Eigen::MatrixXd PHt = P_ * H.transpose();
  const Eigen::MatrixXd S = H * PHt + R;
  const auto S_ldlt = S.ldlt();
  if (gate_chi2 > 0.0 && residual.dot(S_ldlt.solve(residual)) > gate_chi2) return false;
  const Eigen::MatrixXd K = S_ldlt.solve(PHt.transpose()).transpose();  // P H^T S^-1
  x_ = normalized_state(x_ + K * residual);
  // Joseph form: stays symmetric positive semi-definite for any gain.
  const StateMatrix IKH = StateMatrix::Identity() - K * H;
  P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
  return true;
}

}  // namespace farlio::fusion
