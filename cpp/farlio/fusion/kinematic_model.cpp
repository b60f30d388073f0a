#include "farlio/fusion/kinematic_model.hpp"

#include <cmath>
#include <numbers>

#include "farlio/core/se3.hpp"
#include "farlio/fusion/euler.hpp"

namespace farlio::fusion {
namespace {

double clamped_cos_pitch(double pitch_rad) {
  const double c = std::cos(pitch_rad);
  return std::abs(c) < kMinCosPitch ? std::copysign(kMinCosPitch, c) : c;
}

Eigen::Matrix3d rot_x(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }
Eigen::Matrix3d rot_y(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }
Eigen::Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// The tilt as a rotation vector (no turn about z).
Eigen::Vector3d tilt_vector(const StateVector& x) { return {x(kTiltIndex), x(kTiltIndex + 1), 0.0}; }

}  // namespace

Eigen::Vector3d world_gravity(const StateVector& x, double gravity_m_s2) {
  return so3_exp(tilt_vector(x)) * Eigen::Vector3d(0.0, 0.0, -gravity_m_s2);
}

Eigen::Matrix3d level_from_world(const StateVector& x) { return so3_exp(tilt_vector(x)).transpose(); }

Eigen::Matrix3d euler_rate_matrix(const Eigen::Vector3d& rpy) {
  const double sr = std::sin(rpy.x()), cr = std::cos(rpy.x());
  const double cp = clamped_cos_pitch(rpy.y()), tp = std::sin(rpy.y()) / cp;
  Eigen::Matrix3d E;
  E << 1.0, sr * tp, cr * tp,  //
      0.0, cr, -sr,            //
      0.0, sr / cp, cr / cp;
  return E;
}

InputVector corrected_input(const StateVector& x, const InputVector& u) {
  InputVector c = u;
  c.segment<3>(kAccelIndex) -= x.segment<3>(kAccelBiasIndex);
  c.segment<3>(kGyroIndex) -= x.segment<3>(kGyroBiasIndex);
  return c;
}

InputVector make_input(const Eigen::Vector3d& accel_m_s2, const Eigen::Vector3d& gyro_rad_s) {
  InputVector u;
  u << accel_m_s2, gyro_rad_s;
  return u;
}

StateVector state_derivative(const StateVector& x, const InputVector& u_measured, double gravity_m_s2) {
  const InputVector u = corrected_input(x, u_measured);
  const Eigen::Vector3d rpy = x.segment<3>(kAttitudeIndex);
  const Eigen::Vector3d v = x.segment<3>(kVelocityIndex);
  const Eigen::Vector3d a = u.segment<3>(kAccelIndex);
  const Eigen::Vector3d w = u.segment<3>(kGyroIndex);
  const Eigen::Matrix3d R = rotation_from_euler(rpy);
  const Eigen::Vector3d g_world = world_gravity(x, gravity_m_s2);
  StateVector dx = StateVector::Zero();
  dx.segment<3>(kPositionIndex) = R * v;
  dx.segment<3>(kAttitudeIndex) = euler_rate_matrix(rpy) * w;
  dx.segment<3>(kVelocityIndex) = a - w.cross(v) + R.transpose() * g_world;
  return dx;
}

ModelJacobians model_jacobians(const StateVector& x, const InputVector& u_measured, double gravity_m_s2) {
  const InputVector u = corrected_input(x, u_measured);
  const double r = x(kAttitudeIndex), p = x(kAttitudeIndex + 1), y = x(kAttitudeIndex + 2);
  const Eigen::Vector3d v = x.segment<3>(kVelocityIndex);
  const Eigen::Vector3d w = u.segment<3>(kGyroIndex);
  const double sr = std::sin(r), cr = std::cos(r), sp = std::sin(p);
  const double cp = clamped_cos_pitch(p), tp = sp / cp;
  // Derivatives of the elementary rotations: d/da Rx(a) = Rx(a) [e_x]x etc.
  const Eigen::Matrix3d Rx = rot_x(r), Ry = rot_y(p), Rz = rot_z(y);
  const Eigen::Matrix3d dRx = Rx * hat(Eigen::Vector3d::UnitX());
  const Eigen::Matrix3d dRy = Ry * hat(Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d dRz = Rz * hat(Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d g = world_gravity(x, gravity_m_s2);

  ModelJacobians J;
  // p' = R v
  J.df_dx.block<3, 1>(kPositionIndex, kAttitudeIndex + 0) = Rz * Ry * dRx * v;
  J.df_dx.block<3, 1>(kPositionIndex, kAttitudeIndex + 1) = Rz * dRy * Rx * v;
  J.df_dx.block<3, 1>(kPositionIndex, kAttitudeIndex + 2) = dRz * Ry * Rx * v;
  J.df_dx.block<3, 3>(kPositionIndex, kVelocityIndex) = Rz * Ry * Rx;
  // theta' = E(theta) w; with s = sr w_y + cr w_z and c = cr w_y - sr w_z
  const double s = sr * w.y() + cr * w.z();
  const double c = cr * w.y() - sr * w.z();
  J.df_dx.block<3, 1>(kAttitudeIndex, kAttitudeIndex + 0) = Eigen::Vector3d(tp * c, -s, c / cp);
  J.df_dx.block<3, 1>(kAttitudeIndex, kAttitudeIndex + 1) = Eigen::Vector3d(s / (cp * cp), 0.0, s * sp / (cp * cp));
  J.df_du.block<3, 3>(kAttitudeIndex, kGyroIndex) = euler_rate_matrix(x.segment<3>(kAttitudeIndex));
  // v' = a - w x v + R^T g, R^T = Rx^T Ry^T Rz^T
  J.df_dx.block<3, 1>(kVelocityIndex, kAttitudeIndex + 0) = dRx.transpose() * Ry.transpose() * Rz.transpose() * g;
  J.df_dx.block<3, 1>(kVelocityIndex, kAttitudeIndex + 1) = Rx.transpose() * dRy.transpose() * Rz.transpose() * g;
  J.df_dx.block<3, 1>(kVelocityIndex, kAttitudeIndex + 2) = Rx.transpose() * Ry.transpose() * dRz.transpose() * g;
  // g = Exp(t) g0: dg/dt = -[g]x J_l(t), its x and y columns
  const Eigen::Matrix3d dg_dt = -hat(g) * so3_left_jacobian(tilt_vector(x));
  J.df_dx.block<3, 2>(kVelocityIndex, kTiltIndex) = (Rz * Ry * Rx).transpose() * dg_dt.leftCols<2>();
  J.df_dx.block<3, 3>(kVelocityIndex, kVelocityIndex) = -hat(w);
  J.df_du.block<3, 3>(kVelocityIndex, kAccelIndex) = Eigen::Matrix3d::Identity();
  J.df_du.block<3, 3>(kVelocityIndex, kGyroIndex) = hat(v);
  // the biases enter as -u
  J.df_dx.middleCols<3>(kGyroBiasIndex) = -J.df_du.middleCols<3>(kGyroIndex);
  J.df_dx.middleCols<3>(kAccelBiasIndex) = -J.df_du.middleCols<3>(kAccelIndex);
  return J;
}

StateVector normalized_state(const StateVector& x) {
  StateVector out = x;
  Eigen::Vector3d rpy = x.segment<3>(kAttitudeIndex);
  if (std::abs(rpy.y()) > 0.5 * std::numbers::pi) rpy = euler_from_rotation(rotation_from_euler(rpy));
  for (int i = 0; i < 3; ++i) rpy(i) = wrap_angle(rpy(i));
  out.segment<3>(kAttitudeIndex) = rpy;
  return out;
}

StateVector integrate_step(const StateVector& x, const InputVector& u_start, const InputVector& u_mid,
                           const InputVector& u_end, double dt_s, double gravity_m_s2) {
  const double h = dt_s;
  const StateVector k1 = state_derivative(x, u_start, gravity_m_s2);
  const StateVector k2 = state_derivative(x + 0.5 * h * k1, u_mid, gravity_m_s2);
  const StateVector k3 = state_derivative(x + 0.5 * h * k2, u_mid, gravity_m_s2);
  const StateVector k4 = state_derivative(x + h * k3, u_end, gravity_m_s2);
  return normalized_state(x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
}

}  // namespace farlio::fusion
