#pragma once
// IMU grades: the profile's own IMU noise (the default), an ideal IMU, and three datasheet classes
// (consumer, industrial and tactical MEMS) given in datasheet units and converted into the
// generator's NoiseConfig and ImuErrorConfig at the profile's IMU rate (docs/simulation.md, "IMU
// grades"). The figures are typical values of each class, not those of one part.
#include <string>

#include "farlio/sim/config.hpp"

namespace farlio::sim {

enum class ImuGrade { Profile, Ideal, Consumer, Industrial, Tactical };

/// "profile" | "ideal" | "consumer" | "industrial" | "tactical"; throws std::invalid_argument
/// listing the valid names.
ImuGrade parse_imu_grade(const std::string& name);
std::string imu_grade_name(ImuGrade grade);

/// One datasheet class, 1-sigma figures in the units datasheets use.
struct ImuDatasheet {
  double gyro_noise_density_deg_s_sqrt_hz;  ///< rate noise density (angle random walk)
  double gyro_bias_instability_deg_h;       ///< in-run bias stability (Allan deviation floor)
  double gyro_turn_on_bias_deg_s;           ///< bias repeatability from one switch-on to the next
  double gyro_scale_factor_ppm;             ///< sensitivity error
  double gyro_misalignment_mrad;            ///< cross-axis sensitivity, per axis pair
  double gyro_g_sensitivity_deg_s_g;        ///< linear-acceleration effect on the gyro bias
  double accel_noise_density_ug_sqrt_hz;    ///< velocity random walk
  double accel_bias_instability_ug;         ///< in-run bias stability
  double accel_turn_on_bias_mg;             ///< bias repeatability
  double accel_scale_factor_ppm;            ///< sensitivity error
  double accel_misalignment_mrad;           ///< cross-axis sensitivity, per axis pair
};

/// The class figures of Consumer, Industrial or Tactical; throws std::invalid_argument otherwise.
ImuDatasheet imu_datasheet(ImuGrade grade);

/// The mount vibration of a profile's platform (car, race car, hand) used by the datasheet grades.
VibrationConfig platform_vibration(Profile profile);

/// Sets config.noise's IMU fields and config.imu_errors to the grade at config.imu_rate_hz:
/// Profile leaves config unchanged, Ideal removes every IMU error (the LiDAR noise stays), the
/// datasheet classes replace the IMU noise and add the profile's platform vibration when
/// `vibration` is true.
void apply_imu_grade(SimConfig& config, ImuGrade grade, bool vibration = true);

/// The white noise of one sample of an IMU sampling at rate_hz with this noise density.
double white_noise_std_per_sample(double noise_density_per_sqrt_hz, double rate_hz);

/// The rate random walk whose Allan deviation K sqrt(tau / 3) equals the bias instability at
/// tau = kBiasInstabilityTime_s (docs/simulation.md).
double bias_walk_from_instability(double bias_instability);
inline constexpr double kBiasInstabilityTime_s = 100.0;

}  // namespace farlio::sim
