#pragma once
// Gyro bias from standstill (paper: calibration during standstill instead of online estimation):
// while the estimated speed is low and the IMU itself reads rest (|omega| small, | |a| - g |
// small), every gyro reading is a bias sample. The bias is the running mean over a bounded
// window, with the initial bias counted as `prior_samples` samples so that a few samples cannot
// swing it. The accelerometer bias is not estimated (it stays at its configured value).
#include <Eigen/Core>
#include <cstdint>
#include <deque>

#include "farlio/core/config.hpp"

namespace farlio::fusion {

class StandstillGyroBias {
 public:
  StandstillGyroBias(const FusionConfig& config, double gravity_m_s2);

  /// Offers one IMU reading (accelerometer in m/s^2) at the given speed estimate; true if it
  /// was taken as a bias sample.
  bool add(const Eigen::Vector3d& gyro_rad_s, const Eigen::Vector3d& accel_m_s2, double speed_m_s);
  [[nodiscard]] Eigen::Vector3d bias_rad_s() const;
  [[nodiscard]] std::size_t sample_count() const { return window_.size(); }

 private:
  Eigen::Vector3d initial_bias_rad_s_;
  double prior_weight_;
  std::size_t max_samples_;
  double max_speed_m_s_;
  double max_gyro_rad_s_;
  double max_accel_deviation_m_s2_;
  double gravity_m_s2_;
  std::deque<Eigen::Vector3d> window_;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
};

}  // namespace farlio::fusion
