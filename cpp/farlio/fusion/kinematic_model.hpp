#pragma once
// The kinematic motion model of the EKF (paper eqs. 7-8, with the IMU biases and the frame's tilt
// as states): state, input, continuous dynamics, their analytic Jacobians and one integration step.
//   x = [p_world (3), roll/pitch/yaw ZYX (3), v_body (3), b_gyro (3), b_accel (3), tilt (2)]
//   u = [a_m (3), omega_m (3)], the IMU input (specific force, angular rate) in the body frame
//   with a = a_m - b_accel and omega = omega_m - b_gyro:
//   p'     = R(theta) v
//   theta' = E(theta) omega
//   v'     = a - omega x v + R(theta)^T g_world,  g_world = Exp((tilt_x, tilt_y, 0)) (0, 0, -g)
//   b'     = 0, tilt' = 0 (random walks: their noise enters the covariance in the EKF)
// The world frame of the filter is level up to its tilt: gravity in it is turned by the tilt
// about its x and y axes. The frame is levelled when the filter starts (initialization.hpp): at
// rest by the mean specific force, off by the accelerometer's bias (the tilt's initial std is
// fusion.bias.accel_std_m_s2 / g); in motion by a short LiDAR-inertial alignment, off by a few
// degrees. The tilt state lets the filter refine it as the vehicle turns (a tilt is fixed in the
// world, an accelerometer bias in the body). The paper's filter has neither biases nor tilt; with
// zero bias covariance and walk and a zero tilt covariance the two are the same filter.
#include <Eigen/Core>

namespace farlio::fusion {

inline constexpr int kStateDim = 17;
inline constexpr int kInputDim = 6;
inline constexpr int kPositionIndex = 0;    ///< p_world in the state
inline constexpr int kAttitudeIndex = 3;    ///< roll, pitch, yaw in the state
inline constexpr int kVelocityIndex = 6;    ///< v_body in the state
inline constexpr int kGyroBiasIndex = 9;    ///< b_gyro in the state
inline constexpr int kAccelBiasIndex = 12;  ///< b_accel in the state
inline constexpr int kTiltIndex = 15;       ///< the world frame's tilt about its x and y axes (rad)
inline constexpr int kAccelIndex = 0;       ///< a_m in the input
inline constexpr int kGyroIndex = 3;        ///< omega_m in the input
/// |cos(pitch)| is clamped to at least this in E(theta) (the gimbal lock at +-90 deg).
inline constexpr double kMinCosPitch = 1e-9;

using StateVector = Eigen::Matrix<double, kStateDim, 1>;
using StateMatrix = Eigen::Matrix<double, kStateDim, kStateDim>;
using InputVector = Eigen::Matrix<double, kInputDim, 1>;
using InputMatrix = Eigen::Matrix<double, kStateDim, kInputDim>;

/// Gravity in the filter's world frame for the state's tilt: Exp((tilt_x, tilt_y, 0)) (0, 0, -g).
Eigen::Vector3d world_gravity(const StateVector& x, double gravity_m_s2);
/// The rotation from the filter's world frame to the level frame (z against gravity): Exp(tilt)^T.
Eigen::Matrix3d level_from_world(const StateVector& x);

/// u from its parts.
InputVector make_input(const Eigen::Vector3d& accel_m_s2, const Eigen::Vector3d& gyro_rad_s);

/// u with the state's biases removed: [a_m - b_accel, omega_m - b_gyro].
InputVector corrected_input(const StateVector& x, const InputVector& u);

/// Euler-rate matrix E(theta): theta' = E(theta) omega_body (ZYX); also the Jacobian of the
/// angles of R(theta) Exp(delta) with respect to a body-frame rotation delta.
Eigen::Matrix3d euler_rate_matrix(const Eigen::Vector3d& rpy);

/// f(x, u): the state derivative.
StateVector state_derivative(const StateVector& x, const InputVector& u, double gravity_m_s2);

/// df/dx and df/du at (x, u), analytic.
struct ModelJacobians {
  StateMatrix df_dx = StateMatrix::Zero();
  InputMatrix df_du = InputMatrix::Zero();
};
ModelJacobians model_jacobians(const StateVector& x, const InputVector& u, double gravity_m_s2);

/// One classical Runge-Kutta (RK4) step of length dt_s with the input at the step start, the
/// step middle and the step end. The angles of the result are wrapped (pitch kept in
/// [-pi/2, pi/2] by re-deriving the angles from the rotation if it leaves that range).
StateVector integrate_step(const StateVector& x, const InputVector& u_start, const InputVector& u_mid,
                           const InputVector& u_end, double dt_s, double gravity_m_s2);

/// Wraps the angles of x (see integrate_step).
StateVector normalized_state(const StateVector& x);

}  // namespace farlio::fusion
