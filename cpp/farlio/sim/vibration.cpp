#include "farlio/sim/vibration.hpp"

#include <cmath>
#include <numbers>

#include "farlio/sim/random.hpp"

namespace farlio::sim {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Stream index of the gyro and accelerometer phases.
constexpr std::uint64_t kGyro = 0;
constexpr std::uint64_t kAccel = 1;

Eigen::Vector3d uniform_phases(std::uint64_t seed, std::uint64_t sensor) {
  Eigen::Vector3d p;
  for (int a = 0; a < 3; ++a)
    p[a] = kTwoPi * uniform01(seed, Stream::ImuVibrationPhase, sensor, static_cast<std::uint64_t>(a));
  return p;
}

Eigen::Vector3d sinusoids(double angle_rad, const Eigen::Vector3d& phase_rad) {
  return {std::sin(angle_rad + phase_rad.x()), std::sin(angle_rad + phase_rad.y()),
          std::sin(angle_rad + phase_rad.z())};
}
}  // namespace

Vibration::Vibration(const VibrationConfig& config, std::uint64_t seed, double imu_rate_hz)
    : config_(config),
      seed_(seed),
      dt_s_(1.0 / imu_rate_hz),
      nyquist_hz_(0.5 * imu_rate_hz),
      gyro_phase_rad_(uniform_phases(seed, kGyro)),
      accel_phase_rad_(uniform_phases(seed, kAccel)) {}

Vibration::Reading Vibration::next(std::size_t k, double speed_m_s) {
  if (k > 0) wheel_angle_rad_ += 0.5 * (previous_speed_m_s_ + speed_m_s) * dt_s_ / config_.wheel_radius_m;
  previous_speed_m_s_ = speed_m_s;
  Reading r;
  const double wheel_hz = speed_m_s / (kTwoPi * config_.wheel_radius_m);
  if (wheel_hz < nyquist_hz_) {
    r.gyro_rad_s = speed_m_s * config_.gyro_wheel_amplitude_rad_s_per_m_s.cwiseProduct(
                                   sinusoids(wheel_angle_rad_, gyro_phase_rad_));
    r.accel_m_s2 = speed_m_s * config_.accel_wheel_amplitude_m_s2_per_m_s.cwiseProduct(
                                   sinusoids(wheel_angle_rad_, accel_phase_rad_));
  }
  r.gyro_rad_s += speed_m_s * config_.gyro_noise_std_rad_s_per_m_s.cwiseProduct(
                                  standard_normal3(seed_, Stream::ImuGyroVibration, k));
  r.accel_m_s2 += speed_m_s * config_.accel_noise_std_m_s2_per_m_s.cwiseProduct(
                                  standard_normal3(seed_, Stream::ImuAccelVibration, k));
  return r;
}

}  // namespace farlio::sim
