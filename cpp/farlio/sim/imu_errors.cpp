#include "farlio/sim/imu_errors.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "farlio/sim/random.hpp"

namespace farlio::sim {
namespace {
constexpr double kPerPpm = 1e-6;
constexpr double kRadPerMrad = 1e-3;
/// Stream index of the gyro and accelerometer draws of one kind.
constexpr std::uint64_t kGyro = 0;
constexpr std::uint64_t kAccel = 1;

/// I + diag(scale) + off-diagonal misalignment, each term a scaled standard normal.
Mat3d draw_response(std::uint64_t seed, std::uint64_t sensor, double scale_std, double misalignment_std) {
  Mat3d m = Mat3d::Identity();
  const Eigen::Vector3d scale = standard_normal3(seed, Stream::ImuScaleFactor, sensor);
  for (int r = 0; r < 3; ++r) {
    m(r, r) += scale_std * scale[r];
    for (int c = 0; c < 3; ++c) {
      if (c == r) continue;
      const auto entry = static_cast<std::uint64_t>(3 * r + c);
      m(r, c) = misalignment_std * standard_normal(seed, Stream::ImuMisalignment, sensor, entry);
    }
  }
  return m;
}

void require_non_negative(double value, const char* name) {
  if (!(std::isfinite(value) && value >= 0.0))
    throw std::invalid_argument(std::string("ImuErrorConfig: ") + name + " must be finite and non-negative");
}

void require_non_negative(const Eigen::Vector3d& value, const char* name) {
  for (int a = 0; a < 3; ++a) require_non_negative(value[a], name);
}
}  // namespace

ImuErrorDraw draw_imu_errors(const ImuErrorConfig& config, std::uint64_t seed) {
  ImuErrorDraw d;
  d.gyro_turn_on_bias_rad_s = config.gyro_turn_on_bias_std_rad_s * standard_normal3(seed, Stream::ImuTurnOnBias, kGyro);
  d.accel_turn_on_bias_m_s2 =
      config.accel_turn_on_bias_std_m_s2 * standard_normal3(seed, Stream::ImuTurnOnBias, kAccel);
  d.gyro_response = draw_response(seed, kGyro, kPerPpm * config.gyro_scale_factor_std_ppm,
                                  kRadPerMrad * config.gyro_misalignment_std_mrad);
  d.accel_response = draw_response(seed, kAccel, kPerPpm * config.accel_scale_factor_std_ppm,
                                   kRadPerMrad * config.accel_misalignment_std_mrad);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      d.gyro_g_sensitivity_rad_s_per_m_s2(r, c) =
          config.gyro_g_sensitivity_std_rad_s_per_m_s2 *
          standard_normal(seed, Stream::ImuGSensitivity, 0, static_cast<std::uint64_t>(3 * r + c));
  return d;
}

ImuSample apply_imu_errors(const ImuErrorDraw& draw, const ImuSample& ideal) {
  ImuSample out = ideal;
  out.gyro_rad_s = draw.gyro_response * ideal.gyro_rad_s + draw.gyro_g_sensitivity_rad_s_per_m_s2 * ideal.accel_m_s2;
  out.accel_m_s2 = draw.accel_response * ideal.accel_m_s2;
  return out;
}

void validate_imu_errors(const ImuErrorConfig& config) {
  require_non_negative(config.gyro_turn_on_bias_std_rad_s, "gyro_turn_on_bias_std_rad_s");
  require_non_negative(config.accel_turn_on_bias_std_m_s2, "accel_turn_on_bias_std_m_s2");
  require_non_negative(config.gyro_scale_factor_std_ppm, "gyro_scale_factor_std_ppm");
  require_non_negative(config.accel_scale_factor_std_ppm, "accel_scale_factor_std_ppm");
  require_non_negative(config.gyro_misalignment_std_mrad, "gyro_misalignment_std_mrad");
  require_non_negative(config.accel_misalignment_std_mrad, "accel_misalignment_std_mrad");
  require_non_negative(config.gyro_g_sensitivity_std_rad_s_per_m_s2, "gyro_g_sensitivity_std_rad_s_per_m_s2");
  const VibrationConfig& v = config.vibration;
  require_non_negative(v.accel_wheel_amplitude_m_s2_per_m_s, "vibration.accel_wheel_amplitude_m_s2_per_m_s");
  require_non_negative(v.gyro_wheel_amplitude_rad_s_per_m_s, "vibration.gyro_wheel_amplitude_rad_s_per_m_s");
  require_non_negative(v.accel_noise_std_m_s2_per_m_s, "vibration.accel_noise_std_m_s2_per_m_s");
  require_non_negative(v.gyro_noise_std_rad_s_per_m_s, "vibration.gyro_noise_std_rad_s_per_m_s");
  if (!(std::isfinite(v.wheel_radius_m) && v.wheel_radius_m > 0.0))
    throw std::invalid_argument("ImuErrorConfig: vibration.wheel_radius_m must be finite and positive");
}

}  // namespace farlio::sim
