#pragma once
// Configuration of the sequence generator: the profile (scene, trajectory and sensors), the
// seed, the duration and the noise. default_config(profile) gives the documented defaults
// (docs/simulation.md).
#include <Eigen/Core>
#include <cstdint>
#include <string>

namespace farlio::sim {

enum class Profile { Racetrack, Urban, Handheld, Tunnel };

/// "racetrack" | "urban" | "handheld" | "tunnel"; throws std::invalid_argument listing the valid names.
Profile parse_profile(const std::string& name);
std::string profile_name(Profile profile);

struct NoiseConfig {
  double range_noise_std_m = 0.0;              ///< Gaussian, along the ray
  double dropout_probability = 0.0;            ///< chance that a ray returns nothing
  double gyro_noise_std_rad_s = 0.0;           ///< white noise per sample
  double accel_noise_std_m_s2 = 0.0;           ///< white noise per sample
  double gyro_bias_walk_rad_s2_sqrt_hz = 0.0;  ///< bias random walk density
  double accel_bias_walk_m_s3_sqrt_hz = 0.0;   ///< bias random walk density
  Eigen::Vector3d gyro_bias_initial_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_initial_m_s2 = Eigen::Vector3d::Zero();
};

struct SimConfig {
  Profile profile = Profile::Urban;
  std::uint64_t seed = 1;
  double duration_s = 0.0;
  NoiseConfig noise;
  /// True: exact ranges, no dropouts, IMU without noise or bias.
  bool noise_free = false;
  /// Stamp of the sequence start (t = 0) in ns.
  std::int64_t start_stamp_ns = 0;
  double lidar_rate_hz = 0.0;
  double imu_rate_hz = 0.0;
  double gravity_m_s2 = 0.0;
};

/// The documented defaults of a profile.
SimConfig default_config(Profile profile);

}  // namespace farlio::sim
