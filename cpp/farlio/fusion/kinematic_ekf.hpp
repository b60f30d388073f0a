#pragma once
// The kinematic EKF (paper eqs. 7-9): RK4 prediction of the state with the IMU as control
// input, first-order covariance propagation P = A P A^T + B Q B^T + dt Q_bias with A = I + dt df/dx
// and B = dt df/du (Q_bias: the random walks of the bias states), and Joseph-form updates of
// measurement groups with a Mahalanobis gate.
#include <Eigen/Core>

#include "farlio/fusion/kinematic_model.hpp"
#include "farlio/fusion/measurement_model.hpp"

namespace farlio::fusion {

class KinematicEkf {
 public:
  /// input_variance: the diagonal Q of the input noise [a (m^2/s^4), omega (rad^2/s^2)] over one step;
  /// bias_walk_variance: per second, [gyro bias (rad^2/s^3), accel bias (m^2/s^5)] (zero: fixed biases).
  KinematicEkf(double gravity_m_s2, const InputVector& input_variance,
               const InputVector& bias_walk_variance = InputVector::Zero());

  void initialize(const StateVector& x, const StateMatrix& P);
  /// Replaces the input noise Q (the same units as the constructor's).
  void set_input_variance(const InputVector& input_variance) { Q_ = input_variance.asDiagonal(); }
  [[nodiscard]] InputVector input_variance() const { return Q_.diagonal(); }
  [[nodiscard]] bool initialized() const { return initialized_; }

  /// Propagates the state over dt_s with the input at the step start, middle and end.
  void predict(const InputVector& u_start, const InputVector& u_mid, const InputVector& u_end, double dt_s);

  /// Squared Mahalanobis distance r^T (H P H^T + R)^-1 r of a residual r = z - h(x).
  [[nodiscard]] double mahalanobis_squared(MeasurementKind kind, const Eigen::VectorXd& residual,
                                           const Eigen::MatrixXd& R) const;
  /// Updates with the residual r = z - h(x) (angles already wrapped) and covariance R. When
  /// gate_chi2 > 0, the group is rejected (state unchanged, false returned) if its squared
  /// Mahalanobis distance exceeds gate_chi2.
  bool update(MeasurementKind kind, const Eigen::VectorXd& residual, const Eigen::MatrixXd& R, double gate_chi2 = 0.0);

  [[nodiscard]] const StateVector& state() const { return x_; }
  [[nodiscard]] const StateMatrix& covariance() const { return P_; }
  [[nodiscard]] double gravity_m_s2() const { return gravity_m_s2_; }

 private:
  double gravity_m_s2_;
  Eigen::Matrix<double, kInputDim, kInputDim> Q_;
  StateVector bias_walk_ = StateVector::Zero();  ///< diagonal of Q_bias per second
  StateVector x_ = StateVector::Zero();
  StateMatrix P_ = StateMatrix::Identity();
  bool initialized_ = false;
};

}  // namespace farlio::fusion
