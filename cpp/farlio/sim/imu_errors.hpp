#pragma once
// The per-run constants of the IMU error model (ImuErrorConfig) drawn from the seed: turn-on
// biases, the response matrices (scale factor on the diagonal, misalignment off it) and the gyro
// g-sensitivity, and how they turn an ideal reading into a distorted one (before biases, vibration
// and noise are added; imu_model.cpp).
#include <cstdint>

#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"
#include "farlio/sim/config.hpp"

namespace farlio::sim {

struct ImuErrorDraw {
  Eigen::Vector3d gyro_turn_on_bias_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_turn_on_bias_m_s2 = Eigen::Vector3d::Zero();
  Mat3d gyro_response = Mat3d::Identity();                  ///< I + S_g + M_g: reading = response * truth
  Mat3d accel_response = Mat3d::Identity();                 ///< I + S_a + M_a
  Mat3d gyro_g_sensitivity_rad_s_per_m_s2 = Mat3d::Zero();  ///< G: gyro += G * specific force
};

/// The constants of one run: a pure function of (config, seed).
ImuErrorDraw draw_imu_errors(const ImuErrorConfig& config, std::uint64_t seed);

/// The reading of the IMU with these constants when the ideal one is `ideal` (stamp kept).
ImuSample apply_imu_errors(const ImuErrorDraw& draw, const ImuSample& ideal);

/// Throws std::invalid_argument naming the field when a standard deviation or amplitude is
/// negative or not finite, or the wheel radius is not positive.
void validate_imu_errors(const ImuErrorConfig& config);

}  // namespace farlio::sim
