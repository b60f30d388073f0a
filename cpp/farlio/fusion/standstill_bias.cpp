#include "farlio/fusion/standstill_bias.hpp"

#include <algorithm>
#include <cmath>

namespace farlio::fusion {

StandstillGyroBias::StandstillGyroBias(const FusionConfig& c, double gravity_m_s2)
    : initial_bias_rad_s_(c.bias.gyro_init_x_rad_s, c.bias.gyro_init_y_rad_s, c.bias.gyro_init_z_rad_s),
      prior_weight_(std::max(0, c.standstill.prior_samples)),
      max_samples_(static_cast<std::size_t>(std::max(1, c.standstill.window_samples))),
      max_speed_m_s_(c.standstill.max_speed_m_s),
      max_gyro_rad_s_(c.standstill.max_gyro_rad_s),
      max_accel_deviation_m_s2_(c.standstill.max_accel_deviation_m_s2),
      gravity_m_s2_(gravity_m_s2) {}

bool StandstillGyroBias::add(const Eigen::Vector3d& gyro_rad_s, const Eigen::Vector3d& accel_m_s2, double speed_m_s) {
  if (!gyro_rad_s.allFinite() || !accel_m_s2.allFinite() || !(speed_m_s < max_speed_m_s_)) return false;
  if (gyro_rad_s.norm() >= max_gyro_rad_s_) return false;
  if (std::abs(accel_m_s2.norm() - gravity_m_s2_) >= max_accel_deviation_m_s2_) return false;
  window_.push_back(gyro_rad_s);
  sum_ += gyro_rad_s;
  if (window_.size() > max_samples_) {
    sum_ -= window_.front();
    window_.pop_front();
  }
  return true;
}

Eigen::Vector3d StandstillGyroBias::bias_rad_s() const {
  const double n = static_cast<double>(window_.size());
  if (n + prior_weight_ <= 0.0) return initial_bias_rad_s_;
  return (prior_weight_ * initial_bias_rad_s_ + sum_) / (prior_weight_ + n);
}

}  // namespace farlio::fusion
