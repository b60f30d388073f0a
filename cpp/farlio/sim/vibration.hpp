#pragma once
// Vibration of the IMU mount that grows with speed (VibrationConfig): per axis, a sinusoid at the
// wheel rotation frequency and broadband white noise, both with amplitudes proportional to the
// speed. The wheel angle is the travelled distance over the wheel radius (the speed integrated
// with the trapezoid rule between samples). A sinusoid above the Nyquist frequency of the IMU is
// left out, as the anti-aliasing filter of a real IMU would remove it.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "farlio/sim/config.hpp"

namespace farlio::sim {

class Vibration {
 public:
  struct Reading {
    Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
    Eigen::Vector3d accel_m_s2 = Eigen::Vector3d::Zero();
  };

  Vibration(const VibrationConfig& config, std::uint64_t seed, double imu_rate_hz);

  /// The vibration of sample k at body speed speed_m_s; call for k = 0, 1, 2, ... in order.
  Reading next(std::size_t k, double speed_m_s);
  /// The wheel angle of the last sample (travelled distance / wheel radius).
  [[nodiscard]] double wheel_angle_rad() const { return wheel_angle_rad_; }

 private:
  VibrationConfig config_;
  std::uint64_t seed_;
  double dt_s_;
  double nyquist_hz_;
  Eigen::Vector3d gyro_phase_rad_, accel_phase_rad_;
  double wheel_angle_rad_ = 0.0;
  double previous_speed_m_s_ = 0.0;
};

}  // namespace farlio::sim
