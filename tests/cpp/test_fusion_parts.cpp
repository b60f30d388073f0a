// The parts of the fusion front: reference angles, standstill gyro bias, accelerometer unit
// detection, the EKF update (gate, Joseph form, wrapped angles) and the state history.
#include <gtest/gtest.h>

#include <cmath>

#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/kinematic_ekf.hpp"
#include "farlio/fusion/reference_angles.hpp"
#include "farlio/fusion/state_history.hpp"
#include "fusion_test_sim.hpp"

using namespace farlio;
using namespace farlio::fusion;
using namespace farlio::test;

TEST(FusionParts, ReferenceAnglesRecoverTrueRollAndPitchOnAFastCurve) {
  const TestTrajectory traj;  // 30 m/s, 1 rad/s: 30 m/s^2 centripetal acceleration
  ReferenceAngleEstimator est(11, kGravity_m_s2, 0.5);
  constexpr double kDt = 0.01;
  double max_err_deg = 0.0;
  int produced = 0;
  for (int k = 0; k < 300; ++k) {
    const double t = k * kDt;
    const ImuSample m = traj.imu(t);
    const auto a = est.push(seconds_to_ns(t), traj.velocity_body(t), m.accel_m_s2, m.gyro_rad_s);
    if (!a) continue;
    ++produced;
    const Eigen::Vector3d truth = traj.rpy(ns_to_seconds(a->stamp_ns));
    EXPECT_FALSE(a->saturated);
    max_err_deg = std::max(
        {max_err_deg, std::abs(a->roll_rad - truth.x()) * kDegPerRad, std::abs(a->pitch_rad - truth.y()) * kDegPerRad});
  }
  EXPECT_EQ(produced, 300 - 12);  // the window needs taps + 2 samples
  EXPECT_LT(max_err_deg, 0.05);
  std::printf("reference angles: max error %.4f deg\n", max_err_deg);
}

TEST(FusionParts, ReferenceAnglesClampAndNaN) {
  const double g = kGravity_m_s2;
  const double pitch = 40.0 / kDegPerRad;  // beyond the 30 deg clamp
  const auto a = reference_angles_from_gravity(Eigen::Vector3d(g * std::sin(pitch), 0.0, -g * std::cos(pitch)), g, 0.5);
  ASSERT_TRUE(a.has_value());
  EXPECT_TRUE(a->saturated);
  EXPECT_NEAR(a->pitch_rad, std::asin(0.5), 1e-12);
  const double roll = 10.0 / kDegPerRad;
  const auto b = reference_angles_from_gravity(Eigen::Vector3d(0.0, -g * std::sin(roll), -g * std::cos(roll)), g, 0.5);
  ASSERT_TRUE(b.has_value());
  EXPECT_FALSE(b->saturated);
  EXPECT_NEAR(b->roll_rad, roll, 1e-12);
  EXPECT_FALSE(reference_angles_from_gravity(Eigen::Vector3d(NAN, 0.0, -g), g, 0.5).has_value());
}

TEST(FusionParts, GyroBiasConvergesAtStandstill) {
  TestTrajectory still;
  still.speed_m_s = 0.0;
  still.yaw_rate_rad_s = 0.0;
  still.roll_amplitude_rad = still.pitch_amplitude_rad = still.height_amplitude_m = 0.0;
  SimOptions o;
  o.duration_s = 30.0;
  o.imu_hz = 200.0;
  o.gyro_bias_rad_s = Eigen::Vector3d(0.003, -0.002, 0.001);
  o.gyro_noise_std_rad_s = 0.002;
  o.accel_noise_std_m_s2 = 0.02;
  FusionConfig c;  // defaults: standstill.gyro_bias on
  const SimResult r = simulate(still, c, o);
  const Eigen::Vector3d err = r.stats.gyro_bias_rad_s - o.gyro_bias_rad_s;
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(err(i)), std::max(0.1 * std::abs(o.gyro_bias_rad_s(i)), 1e-4)) << i;
  }
  EXPECT_GT(r.stats.bias_samples, 5000);
  std::printf("standstill bias estimate %.5f %.5f %.5f rad/s from %lld samples\n", r.stats.gyro_bias_rad_s.x(),
              r.stats.gyro_bias_rad_s.y(), r.stats.gyro_bias_rad_s.z(), static_cast<long long>(r.stats.bias_samples));
  c.standstill.gyro_bias = false;  // the bias state of the filter alone learns it from the LiDAR attitude
  const Eigen::Vector3d filter_err = simulate(still, c, o).stats.gyro_bias_rad_s - o.gyro_bias_rad_s;
  EXPECT_LT(filter_err.cwiseAbs().maxCoeff(), 3e-4) << filter_err.transpose();
  c.bias.estimate = false;  // ablation (the paper's filter): the bias stays at its initial value
  EXPECT_EQ(simulate(still, c, o).stats.gyro_bias_rad_s, Eigen::Vector3d::Zero());
}

TEST(FusionParts, AccelerometerInGIsDetectedAndScaled) {
  const TestTrajectory slow{1.5, 0.3, 0.02, 0.02, 0.05, 0.5};
  SimOptions o;
  o.lidar_hz = 0.0;  // prediction only: an unscaled accelerometer would fall ~4 m in 1 s
  o.imu_hz = 200.0;
  o.accel_in_g = true;
  const SimResult r = simulate(slow, plain_config(), o);
  EXPECT_TRUE(r.stats.accel_in_g);
  EXPECT_FALSE(r.stats.accel_unit_message.empty());
  EXPECT_LT(r.max_position_error_m(), 0.02);
  o.accel_in_g = false;
  const SimResult normal = simulate(slow, plain_config(), o);
  EXPECT_FALSE(normal.stats.accel_in_g);
  EXPECT_TRUE(normal.stats.accel_unit_message.empty());
}

TEST(FusionParts, EkfUpdateGatesWrapsAndStaysSymmetric) {
  InputVector q = InputVector::Constant(0.01);
  KinematicEkf ekf(kGravity_m_s2, q);
  StateVector x = StateVector::Zero();
  x(kAttitudeIndex + 2) = 3.1;  // yaw near +pi
  ekf.initialize(x, StateMatrix::Identity() * 0.01);
  // A yaw measurement at -3.1 is 0.083 rad away across the wrap, not 6.2 rad.
  const Eigen::Vector3d z(0.0, 0.0, -3.1);
  const Eigen::VectorXd r =
      measurement_difference(MeasurementKind::kOrientation, z, measure(MeasurementKind::kOrientation, x));
  EXPECT_NEAR(r(2), 2.0 * std::numbers::pi - 6.2, 1e-12);
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity() * 0.01;
  EXPECT_TRUE(ekf.update(MeasurementKind::kOrientation, r, R, 16.27));
  // Equal prior and measurement variance: the estimate moves half way, across the wrap.
  EXPECT_NEAR(wrap_angle(ekf.state()(kAttitudeIndex + 2) - 3.1), 0.5 * r(2), 1e-9);
  EXPECT_NEAR(ekf.covariance()(kAttitudeIndex + 2, kAttitudeIndex + 2), 0.005, 1e-12);
  EXPECT_LT((ekf.covariance() - ekf.covariance().transpose()).norm(), 1e-15);
  // 5 m off with 0.1 m prior and measurement std: d^2 = 25 / 0.02 > 16.27, rejected, unchanged.
  const StateVector before = ekf.state();
  EXPECT_FALSE(ekf.update(MeasurementKind::kPosition, Eigen::Vector3d(5.0, 0.0, 0.0), R, 16.27));
  EXPECT_EQ(ekf.state(), before);
  EXPECT_NEAR(ekf.mahalanobis_squared(MeasurementKind::kPosition, Eigen::Vector3d(5.0, 0.0, 0.0), R), 1250.0, 1e-9);
}

TEST(FusionParts, HistoryInterpolatesAndForgets) {
  StateHistory h(5);
  for (int k = 0; k < 8; ++k) {
    StateVector x = StateVector::Zero();
    x(0) = k;
    x(kAttitudeIndex + 2) = 0.1 * k;
    h.push(seconds_to_ns(0.01 * k), x);
  }
  EXPECT_EQ(h.size(), 5u);
  EXPECT_EQ(h.oldest().stamp_ns, seconds_to_ns(0.03));
  EXPECT_FALSE(h.state_at(seconds_to_ns(0.02)).has_value());
  const auto mid = h.state_at(seconds_to_ns(0.055));
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR((*mid)(0), 5.5, 1e-9);
  EXPECT_NEAR((*mid)(kAttitudeIndex + 2), 0.55, 1e-9);
}
