#pragma once
// Configuration of the sequence generator: the profile (scene, trajectory and sensors), the
// seed, the duration, the noise and the IMU error model. default_config(profile) gives the
// documented defaults (docs/simulation.md); imu_grade.hpp sets the IMU to a datasheet class.
#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "farlio/sim/lidar_model.hpp"

namespace farlio::sim {

enum class Profile { Racetrack, Urban, Handheld, Tunnel, Garage };

/// "racetrack" | "urban" | "handheld" | "tunnel" | "garage"; throws std::invalid_argument listing the valid names.
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

/// Vibration of the IMU mount that grows with speed (docs/simulation.md, "IMU error model"): a
/// sinusoid at the wheel rotation frequency speed / (2 pi wheel_radius_m), one random phase per
/// axis, plus broadband white noise, both with amplitudes proportional to the speed (per axis,
/// body frame). All zero (the default): no vibration.
struct VibrationConfig {
  double wheel_radius_m = 0.3;                                                   ///< sets the wheel-order frequency
  Eigen::Vector3d accel_wheel_amplitude_m_s2_per_m_s = Eigen::Vector3d::Zero();  ///< sinusoid amplitude / speed
  Eigen::Vector3d gyro_wheel_amplitude_rad_s_per_m_s = Eigen::Vector3d::Zero();  ///< sinusoid amplitude / speed
  Eigen::Vector3d accel_noise_std_m_s2_per_m_s = Eigen::Vector3d::Zero();        ///< broadband, per sample / speed
  Eigen::Vector3d gyro_noise_std_rad_s_per_m_s = Eigen::Vector3d::Zero();        ///< broadband, per sample / speed

  [[nodiscard]] bool any() const;
};

/// IMU errors beyond NoiseConfig's white noise, bias walk and fixed initial bias (docs/simulation.md,
/// "IMU error model"). The per-run constants are drawn from the seed (standard deviations per axis or
/// matrix entry); readings are gyro = (I + S_g + M_g) w + G f, accel = (I + S_a + M_a) f, before
/// biases and noise. All zero (the default): no such error, and the IMU is bit-identical to the one
/// NoiseConfig alone gives.
struct ImuErrorConfig {
  double gyro_turn_on_bias_std_rad_s = 0.0;            ///< per axis, constant over a run, added to the initial bias
  double accel_turn_on_bias_std_m_s2 = 0.0;            ///< per axis, constant over a run, added to the initial bias
  double gyro_scale_factor_std_ppm = 0.0;              ///< diagonal S_g, per axis
  double accel_scale_factor_std_ppm = 0.0;             ///< diagonal S_a, per axis
  double gyro_misalignment_std_mrad = 0.0;             ///< off-diagonal M_g (cross-axis coupling), per entry
  double accel_misalignment_std_mrad = 0.0;            ///< off-diagonal M_a (cross-axis coupling), per entry
  double gyro_g_sensitivity_std_rad_s_per_m_s2 = 0.0;  ///< G: gyro reading per unit specific force, per entry
  VibrationConfig vibration;

  [[nodiscard]] bool any() const;
};

struct SimConfig {
  Profile profile = Profile::Urban;
  std::uint64_t seed = 1;
  double duration_s = 0.0;
  NoiseConfig noise;
  ImuErrorConfig imu_errors;
  /// True: exact ranges, no dropouts, IMU without noise, bias or any other error.
  bool noise_free = false;
  /// Stamp of the sequence start (t = 0) in ns.
  std::int64_t start_stamp_ns = 0;
  /// Where the recording begins in the profile's motion, in seconds: t = 0 of the sequence is this
  /// instant of the motion. 0 (the default): at the profile's start, at rest; later: a recording
  /// that begins while the body already moves (a cut bag, a node restarted at speed).
  double motion_start_s = 0.0;
  /// The LiDAR on the vehicle: the profile's own sensors (Profile, the default) or one sensor of a
  /// named model in their place, mounted where the profile's first sensor is (lidar_model.hpp).
  LidarModel lidar_model = LidarModel::Profile;
  double lidar_rate_hz = 0.0;
  double imu_rate_hz = 0.0;
  /// The IMU's samples fall this long after the whole IMU periods of the sequence clock, in [0,
  /// 1 / imu_rate_hz): an IMU is not phase-locked to the LiDAR or to the fusion's step grid.
  double imu_time_offset_s = 0.0;
  double gravity_m_s2 = 0.0;
};

/// The documented defaults of a profile.
SimConfig default_config(Profile profile);

}  // namespace farlio::sim
