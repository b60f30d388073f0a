#include "farlio/sim/config.hpp"

#include <stdexcept>

namespace farlio::sim {
namespace {
constexpr std::int64_t kDefaultStartStamp_ns = 1'700'000'000'000'000'000;
constexpr double kGravity_m_s2 = 9.81;

struct ProfileDefaults {
  double duration_s, lidar_rate_hz, imu_rate_hz;
  NoiseConfig noise;
};

/// The urban car's LiDAR and IMU noise (urban, tunnel and garage).
NoiseConfig car_noise() {
  return NoiseConfig{
      0.02, 0.01, 0.003, 0.05, 2e-5, 3e-4, Eigen::Vector3d(0.001, -0.0015, 0.0008), Eigen::Vector3d(0.04, 0.03, -0.05)};
}

ProfileDefaults defaults_of(Profile p) {
  switch (p) {
    case Profile::Racetrack:      // engine and kerb vibration: high IMU noise
      return {85.0, 20.0, 800.0,  // 2 s rest, standing start and one lap take 82.7 s
              NoiseConfig{0.02, 0.02, 0.02, 0.5, 2e-4, 2e-3, Eigen::Vector3d(0.003, -0.002, 0.001),
                          Eigen::Vector3d(0.08, -0.05, 0.06)}};
    case Profile::Urban: return {120.0, 10.0, 100.0, car_noise()};
    case Profile::Tunnel: return {45.0, 10.0, 100.0, car_noise()};   // the urban car's sensors
    case Profile::Garage: return {180.0, 10.0, 100.0, car_noise()};  // the same; the route ends at 183.5 s
    case Profile::Handheld:
      return {90.0, 10.0, 200.0,
              NoiseConfig{0.01, 0.01, 0.005, 0.08, 4e-5, 6e-4, Eigen::Vector3d(-0.002, 0.001, 0.0015),
                          Eigen::Vector3d(-0.06, 0.04, 0.05)}};
  }
  throw std::invalid_argument("unknown profile");
}
}  // namespace

bool VibrationConfig::any() const {
  return !accel_wheel_amplitude_m_s2_per_m_s.isZero(0.0) || !gyro_wheel_amplitude_rad_s_per_m_s.isZero(0.0) ||
         !accel_noise_std_m_s2_per_m_s.isZero(0.0) || !gyro_noise_std_rad_s_per_m_s.isZero(0.0);
}

bool ImuErrorConfig::any() const {
  return gyro_turn_on_bias_std_rad_s != 0.0 || accel_turn_on_bias_std_m_s2 != 0.0 || gyro_scale_factor_std_ppm != 0.0 ||
         accel_scale_factor_std_ppm != 0.0 || gyro_misalignment_std_mrad != 0.0 || accel_misalignment_std_mrad != 0.0 ||
         gyro_g_sensitivity_std_rad_s_per_m_s2 != 0.0 || vibration.any();
}

Profile parse_profile(const std::string& name) {
  if (name == "racetrack") return Profile::Racetrack;
  if (name == "urban") return Profile::Urban;
  if (name == "handheld") return Profile::Handheld;
  if (name == "tunnel") return Profile::Tunnel;
  if (name == "garage") return Profile::Garage;
  throw std::invalid_argument("unknown simulation profile '" + name +
                              "' (valid: racetrack, urban, handheld, tunnel, garage)");
}

std::string profile_name(Profile profile) {
  switch (profile) {
    case Profile::Racetrack: return "racetrack";
    case Profile::Urban: return "urban";
    case Profile::Handheld: return "handheld";
    case Profile::Tunnel: return "tunnel";
    case Profile::Garage: return "garage";
  }
  throw std::invalid_argument("unknown profile");
}

SimConfig default_config(Profile profile) {
  const ProfileDefaults d = defaults_of(profile);
  SimConfig c;
  c.profile = profile;
  c.duration_s = d.duration_s;
  c.noise = d.noise;
  c.start_stamp_ns = kDefaultStartStamp_ns;
  c.lidar_rate_hz = d.lidar_rate_hz;
  c.imu_rate_hz = d.imu_rate_hz;
  c.gravity_m_s2 = kGravity_m_s2;
  return c;
}

}  // namespace farlio::sim
