// The IMU's noise measured on its samples (fusion::ImuNoiseMeter): white noise of a known std on
// top of a vehicle's motion (a turn whose rate changes, a bump) comes out within a few percent per
// axis over five batches, whatever the motion, and averaged over a filter step as sqrt(samples a step) less; an IMU
// slower than the step keeps one sample's std; a dropped sample does not read as noise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <tuple>

#include "farlio/fusion/imu_noise.hpp"

using namespace farlio;
using fusion::ImuNoise;
using fusion::ImuNoiseMeter;

namespace {

constexpr double kStep_s = 0.01;

/// The motion's rates at t: a slalom whose yaw rate swings by 0.5 rad/s every 4 s, a 3 m/s^2
/// braking pulse and a 2 g bump of 50 ms at 1 s.
void motion(double t, Eigen::Vector3d& gyro, Eigen::Vector3d& accel) {
  gyro = {0.02 * std::sin(3.0 * t), 0.01 * std::cos(2.0 * t), 0.5 * std::sin(2.0 * std::numbers::pi * t / 4.0)};
  accel = {-3.0 * std::sin(0.5 * t), 0.5 * std::sin(2.0 * std::numbers::pi * t / 4.0), 9.81};
  if (t > 1.0 && t < 1.05) accel.z() += 19.6;
}

/// Feeds `seconds` of samples at rate_hz with white noise of the given stds; every drop_every-th
/// sample missing (0: none). Returns the last estimate.
ImuNoise measure(double rate_hz, double gyro_std, double accel_std, double seconds, int drop_every = 0,
                 unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  ImuNoiseMeter meter;
  const auto n = static_cast<int>(seconds * rate_hz);
  for (int k = 0; k < n; ++k) {
    if (drop_every > 0 && k % drop_every == drop_every - 1) continue;
    const double t = k / rate_hz;
    Eigen::Vector3d gyro, accel;
    motion(t, gyro, accel);
    for (int a = 0; a < 3; ++a) {
      gyro[a] += gyro_std * unit(rng);
      accel[a] += accel_std * unit(rng);
    }
    meter.add(static_cast<std::int64_t>(std::llround(t * 1e9)), gyro, accel);
  }
  EXPECT_TRUE(meter.noise().has_value());
  return meter.noise().value_or(ImuNoise{});
}

}  // namespace

class ImuNoiseMeterRates : public ::testing::TestWithParam<std::tuple<double, double, double>> {};

TEST_P(ImuNoiseMeterRates, FindsTheWhiteNoiseUnderTheMotion) {
  const auto [rate_hz, gyro_std, accel_std] = GetParam();
  const ImuNoise noise = measure(rate_hz, gyro_std, accel_std, 5.0 * ImuNoiseMeter::kBatchSamples / rate_hz);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(noise.gyro_std_rad_s[a], gyro_std, 0.08 * gyro_std) << "axis " << a;
    EXPECT_NEAR(noise.accel_std_m_s2[a], accel_std, 0.08 * accel_std) << "axis " << a;
  }
  EXPECT_NEAR(noise.sample_period_s, 1.0 / rate_hz, 1e-6);
  // over a 10 ms step: sqrt(rate * step) samples' mean
  const double samples_a_step = rate_hz * kStep_s;
  EXPECT_NEAR(noise.gyro_step_std_rad_s(kStep_s).maxCoeff(), gyro_std / std::sqrt(samples_a_step),
              0.1 * gyro_std / std::sqrt(samples_a_step));
}

// a vibrating race car's IMU at 800 Hz (3e-3 rad/s/sqrt(Hz), 7e-2 m/s^2/sqrt(Hz)), a MEMS IMU at
// 200 Hz, a quiet one at 100 Hz
INSTANTIATE_TEST_SUITE_P(Imus, ImuNoiseMeterRates,
                         ::testing::Values(std::make_tuple(800.0, 3e-3 * std::sqrt(800.0), 7e-2 * std::sqrt(800.0)),
                                           std::make_tuple(200.0, 5e-3, 8e-2), std::make_tuple(100.0, 3e-3, 5e-2)));

TEST(ImuNoiseMeter, AnImuSlowerThanTheStepKeepsOneSamplesStd) {
  ImuNoise noise;
  noise.gyro_std_rad_s = Eigen::Vector3d::Constant(0.01);
  noise.accel_std_m_s2 = Eigen::Vector3d::Constant(0.1);
  noise.sample_period_s = 0.1;  // 10 Hz
  EXPECT_DOUBLE_EQ(noise.gyro_step_std_rad_s(kStep_s).maxCoeff(), 0.01);
  EXPECT_DOUBLE_EQ(noise.accel_step_std_m_s2(kStep_s).maxCoeff(), 0.1);
  noise.sample_period_s = 0.0025;  // 400 Hz: four samples a step
  EXPECT_DOUBLE_EQ(noise.accel_step_std_m_s2(kStep_s).maxCoeff(), 0.05);
}

TEST(ImuNoiseMeter, ATenHertzImuIsMeasuredWithinTenSeconds) {
  // KITTI raw's OXTS rate: 100 samples in 10 s make an estimate (its rate, for the run's summary)
  const ImuNoise noise = measure(10.0, 3e-3, 5e-2, ImuNoiseMeter::kMaxBatch_s + 0.3);
  EXPECT_NEAR(noise.sample_period_s, 0.1, 1e-6);
  // the slalom's yaw rate changes by 0.012 rad/s in a second difference 0.1 s apart, four times the
  // noise: at 10 Hz the motion adds to the estimate (a filter then trusts the IMU less, not more)
  EXPECT_GE(noise.gyro_std_rad_s.maxCoeff(), 0.8 * 3e-3);
  EXPECT_LE(noise.gyro_std_rad_s.maxCoeff(), 2.0 * 3e-3);
}

TEST(ImuNoiseMeter, DroppedSamplesDoNotReadAsNoise) {
  // every 7th sample missing: the differences across a gap are left out, not read as a slope's
  const ImuNoise noise = measure(200.0, 5e-3, 8e-2, 6.0 * ImuNoiseMeter::kBatchSamples / 200.0, /*drop_every=*/7);
  EXPECT_NEAR(noise.gyro_std_rad_s.maxCoeff(), 5e-3, 0.1 * 5e-3);
  EXPECT_NEAR(noise.accel_std_m_s2.maxCoeff(), 8e-2, 0.1 * 8e-2);
  EXPECT_NEAR(noise.sample_period_s, 0.005, 1e-6);
}

TEST(ImuNoiseMeter, NoEstimateBeforeABatchAndNoneFromNonFiniteOrOldSamples) {
  ImuNoiseMeter meter;
  const Eigen::Vector3d g(0.0, 0.0, 0.1), a(0.0, 0.0, 9.81);
  for (int k = 0; k + 1 < static_cast<int>(ImuNoiseMeter::kBatchSamples); ++k) meter.add(k * 5'000'000LL, g, a);
  EXPECT_FALSE(meter.noise().has_value());
  meter.add(0, g, a);  // older: ignored
  meter.add(std::numeric_limits<std::int64_t>::max() / 2, Eigen::Vector3d::Constant(NAN), a);
  EXPECT_FALSE(meter.noise().has_value());
  // a motion without noise measures (close to) none
  for (int k = 0; k < 2 * static_cast<int>(ImuNoiseMeter::kBatchSamples); ++k) {
    const double t = 10.0 + k * 0.005;
    Eigen::Vector3d gyro, accel;
    motion(t, gyro, accel);
    meter.add(static_cast<std::int64_t>(std::llround(t * 1e9)), gyro, accel);
  }
  ASSERT_TRUE(meter.noise().has_value());
  EXPECT_LT(meter.noise()->gyro_std_rad_s.maxCoeff(), 1e-4);
  EXPECT_LT(meter.noise()->accel_std_m_s2.maxCoeff(), 1e-3);
}
