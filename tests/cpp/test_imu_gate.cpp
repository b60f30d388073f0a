// The IMU sample gate (fusion/imu_gate.hpp): corrupt samples are rejected with a reason naming
// the field, ordinary signals (noise, vibration, real steps) pass.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "farlio/fusion/imu_gate.hpp"

namespace farlio {
namespace {

using fusion::ImuGate;
constexpr std::int64_t kPeriodNs = 5'000'000;  // 200 Hz

ImuSample sample(std::int64_t k, const Eigen::Vector3d& accel, const Eigen::Vector3d& gyro) {
  return ImuSample{k * kPeriodNs, gyro, accel};
}

/// A vibrating, turning vehicle: gravity, vibration of +-8 m/s^2 at 40 Hz, yaw rate 0.5 rad/s.
ImuSample ordinary(std::int64_t k, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, 0.3);
  const double t = static_cast<double>(k) * 0.005;
  const Eigen::Vector3d a(noise(rng) + 8.0 * std::sin(2.0 * M_PI * 40.0 * t), noise(rng), 9.81 + noise(rng));
  const Eigen::Vector3d w(0.01 * noise(rng), 0.01 * noise(rng), 0.5 + 0.02 * noise(rng));
  return sample(k, a, w);
}

TEST(ImuGate, OrdinarySignalsPass) {
  std::mt19937 rng(4);
  ImuGate gate(FusionConfig{});
  for (std::int64_t k = 0; k < 20000; ++k) EXPECT_EQ(gate.check(ordinary(k, rng), 1.0), "") << k;
}

TEST(ImuGate, CorruptSamplesAreRejectedWithTheirField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    Eigen::Vector3d accel, gyro;
    const char* names;  // what the reason must mention
  };
  const Case cases[] = {
      {{1e30, 0.0, 9.81}, {0.0, 0.0, 0.5}, "fusion.imu_gate.max_accel_m_s2"},    // a bit flip
      {{1e4, 0.0, 9.81}, {0.0, 0.0, 0.5}, "fusion.imu_gate.max_accel_m_s2"},     // a 1e4 m/s^2 spike
      {{0.0, 0.0, 9.81}, {0.0, 0.0, 40.0}, "fusion.imu_gate.max_gyro_rad_s"},    // over full scale
      {{0.0, 0.0, 9.81}, {30.0, 0.0, 0.5}, "fusion.imu_gate.spike_gyro_rad_s"},  // within full scale: a spike
      {{90.0, 0.0, 9.81}, {0.0, 0.0, 0.5}, "fusion.imu_gate.spike_accel_m_s2"},  // within full scale: a spike
      {{nan, 0.0, 9.81}, {0.0, 0.0, 0.5}, "non-finite"},
  };
  for (const Case& c : cases) {
    std::mt19937 rng(5);
    ImuGate gate(FusionConfig{});
    std::int64_t k = 0;
    for (; k < 100; ++k) ASSERT_EQ(gate.check(ordinary(k, rng), 1.0), "");
    const std::string why = gate.check(sample(k++, c.accel, c.gyro), 1.0);
    EXPECT_NE(why.find(c.names), std::string::npos) << c.names << ": " << why;
    // the signal after it is accepted again
    for (int i = 0; i < 20; ++i, ++k) EXPECT_EQ(gate.check(ordinary(k, rng), 1.0), "") << c.names;
  }
}

TEST(ImuGate, ARealStepPassesOnceItHasLastedHalfTheWindow) {
  FusionConfig config;
  ImuGate gate(config);
  std::int64_t k = 0;
  for (; k < 50; ++k) ASSERT_EQ(gate.check(sample(k, {0.0, 0.0, 9.81}, Eigen::Vector3d::Zero()), 1.0), "");
  // the gyro jumps to 12 rad/s and stays (a hard turn-in): a spike at first, then the signal
  int rejected = 0;
  for (int i = 0; i < 2 * config.imu_gate.spike_window_samples; ++i, ++k) {
    rejected += !gate.check(sample(k, {0.0, 0.0, 9.81}, {0.0, 0.0, 12.0}), 1.0).empty();
  }
  EXPECT_GT(rejected, 0);
  EXPECT_LE(rejected, config.imu_gate.spike_window_samples / 2 + 1);
}

TEST(ImuGate, AnAccelerometerInGIsJudgedInMetresPerSecondSquared) {
  ImuGate gate(FusionConfig{});
  constexpr double kG = 9.81;
  for (std::int64_t k = 0; k < 50; ++k)
    ASSERT_EQ(gate.check(sample(k, {0.0, 0.0, 1.0}, Eigen::Vector3d::Zero()), kG), "");
  // 6 g off the median: a spike in m/s^2 (59 > 50), although 6 < 50 in the raw unit
  EXPECT_NE(gate.check(sample(50, {6.0, 0.0, 1.0}, Eigen::Vector3d::Zero()), kG), "");
}

}  // namespace
}  // namespace farlio
