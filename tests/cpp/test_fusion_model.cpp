// The kinematic model: Euler conversions, f(x, u) against an analytic trajectory, and the
// analytic Jacobians against central differences.
#include <gtest/gtest.h>

#include <random>

#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/kinematic_model.hpp"
#include "farlio/fusion/measurement_model.hpp"
#include "fusion_test_trajectory.hpp"

using namespace farlio;
using namespace farlio::fusion;

namespace {
constexpr double kDiffStep = 1e-6;     // central-difference step
constexpr double kJacobianTol = 1e-5;  // absolute tolerance of a Jacobian entry
constexpr int kRandomCases = 50;

StateVector true_state(const test::TestTrajectory& traj, double t) {
  StateVector x = StateVector::Zero();  // zero biases
  x.head<9>() << traj.at(t).p, traj.rpy(t), traj.velocity_body(t);
  return x;
}
InputVector true_input(const test::TestTrajectory& traj, double t) {
  const ImuSample m = traj.imu(t);
  return make_input(m.accel_m_s2, m.gyro_rad_s);
}
}  // namespace

TEST(FusionModel, EulerRoundTripAndWrap) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> ang(-3.0, 3.0), pitch(-1.5, 1.5);
  for (int i = 0; i < kRandomCases; ++i) {
    const Eigen::Vector3d rpy(ang(rng), pitch(rng), ang(rng));
    const Eigen::Matrix3d R = rotation_from_euler(rpy);
    EXPECT_LT((R - test::TestTrajectory::rotation(rpy)).norm(), 1e-12);
    EXPECT_LT((euler_from_rotation(R) - rpy).norm(), 1e-9);
  }
  EXPECT_NEAR(wrap_angle(3.5), 3.5 - 2.0 * std::numbers::pi, 1e-12);
  EXPECT_NEAR(wrap_angle(-std::numbers::pi), std::numbers::pi, 1e-12);
  EXPECT_NEAR(wrap_angle(7.0 * std::numbers::pi + 0.1), -std::numbers::pi + 0.1, 1e-9);
}

TEST(FusionModel, DerivativeMatchesAnalyticTrajectory) {
  const test::TestTrajectory traj;
  for (double t : {0.0, 0.37, 1.2, 2.9}) {
    const StateVector f = state_derivative(true_state(traj, t), true_input(traj, t), test::kGravity_m_s2);
    const StateVector numeric = (true_state(traj, t + kDiffStep) - true_state(traj, t - kDiffStep)) / (2 * kDiffStep);
    EXPECT_LT((f - numeric).norm(), 1e-5 * (1.0 + numeric.norm())) << "t=" << t << "\n"
                                                                   << f.transpose() << "\n"
                                                                   << numeric.transpose();
  }
}

TEST(FusionModel, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int c = 0; c < kRandomCases; ++c) {
    StateVector x;
    for (int i = 0; i < kStateDim; ++i) x(i) = 10.0 * uni(rng);
    x(kAttitudeIndex) = 3.0 * uni(rng);
    x(kAttitudeIndex + 1) = 1.4 * uni(rng);  // stay away from the gimbal lock
    x(kAttitudeIndex + 2) = 3.0 * uni(rng);
    InputVector u;
    for (int i = 0; i < kInputDim; ++i) u(i) = 5.0 * uni(rng);
    const ModelJacobians J = model_jacobians(x, u, test::kGravity_m_s2);
    StateMatrix dfdx;
    for (int i = 0; i < kStateDim; ++i) {
      StateVector d = StateVector::Zero();
      d(i) = kDiffStep;
      dfdx.col(i) =
          (state_derivative(x + d, u, test::kGravity_m_s2) - state_derivative(x - d, u, test::kGravity_m_s2)) /
          (2 * kDiffStep);
    }
    InputMatrix dfdu;
    for (int i = 0; i < kInputDim; ++i) {
      InputVector d = InputVector::Zero();
      d(i) = kDiffStep;
      dfdu.col(i) =
          (state_derivative(x, u + d, test::kGravity_m_s2) - state_derivative(x, u - d, test::kGravity_m_s2)) /
          (2 * kDiffStep);
    }
    const double scale = 1.0 + dfdx.cwiseAbs().maxCoeff();
    EXPECT_LT((J.df_dx - dfdx).cwiseAbs().maxCoeff(), kJacobianTol * scale) << "case " << c << "\n" << J.df_dx - dfdx;
    EXPECT_LT((J.df_du - dfdu).cwiseAbs().maxCoeff(), kJacobianTol * scale) << "case " << c;
  }
}

TEST(FusionModel, Rk4StepFollowsTheTruth) {
  const test::TestTrajectory traj;
  constexpr double kDt = 0.01;
  StateVector x = true_state(traj, 0.0);
  for (int k = 0; k < 100; ++k) {
    const double t = k * kDt;
    x = integrate_step(x, true_input(traj, t), true_input(traj, t + 0.5 * kDt), true_input(traj, t + kDt), kDt,
                       test::kGravity_m_s2);
  }
  const StateVector truth = true_state(traj, 1.0);
  EXPECT_LT((x - truth).head<3>().norm(), 1e-4);  // RK4 at 100 Hz on a 30 m/s curve: sub-mm
  EXPECT_LT((x - truth).segment<3>(kAttitudeIndex).norm(), 1e-6);
}

TEST(FusionModel, ReferenceAnglesAreRollAndPitchAgainstGravityThroughTheTilt) {
  // what an accelerometer at rest measures (the specific force, up in the body frame) levels the
  // body as the reference-angle model says, for any attitude and a tilted world frame
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int c = 0; c < kRandomCases; ++c) {
    StateVector x = StateVector::Zero();
    x.segment<3>(kAttitudeIndex) = Eigen::Vector3d(0.5 * uni(rng), 0.5 * uni(rng), 3.0 * uni(rng));
    x.segment<2>(kTiltIndex) = Eigen::Vector2d(0.1 * uni(rng), 0.1 * uni(rng));
    const Eigen::Vector3d up_body =
        -rotation_from_euler(x.segment<3>(kAttitudeIndex)).transpose() * world_gravity(x, test::kGravity_m_s2);
    const double roll = std::atan2(up_body.y(), up_body.z());
    const double pitch = std::atan2(-up_body.x(), std::hypot(up_body.y(), up_body.z()));
    const Eigen::VectorXd h = measure(MeasurementKind::kRollPitch, x);
    EXPECT_NEAR(h(0), roll, 1e-12) << "case " << c;
    EXPECT_NEAR(h(1), pitch, 1e-12) << "case " << c;
    // its Jacobian against central differences of the model over the attitude and the tilt
    const Eigen::MatrixXd H = measurement_jacobian(MeasurementKind::kRollPitch, x);
    for (const int i : {kAttitudeIndex, kAttitudeIndex + 1, kAttitudeIndex + 2, kTiltIndex, kTiltIndex + 1}) {
      StateVector plus = x, minus = x;
      plus(i) += 1e-5;
      minus(i) -= 1e-5;
      const Eigen::VectorXd d =
          (measure(MeasurementKind::kRollPitch, plus) - measure(MeasurementKind::kRollPitch, minus)) / 2e-5;
      EXPECT_LT((H.col(i) - d).cwiseAbs().maxCoeff(), 1e-6) << "case " << c << " state " << i;
    }
  }
  // no tilt: the selector of roll and pitch
  StateVector level = StateVector::Zero();
  level.segment<3>(kAttitudeIndex) = Eigen::Vector3d(0.1, -0.2, 2.0);
  EXPECT_EQ(measure(MeasurementKind::kRollPitch, level), level.segment<2>(kAttitudeIndex));
}
