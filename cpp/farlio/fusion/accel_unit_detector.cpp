#include "farlio/fusion/accel_unit_detector.hpp"

#include <algorithm>
#include <cmath>

namespace farlio::fusion {

AccelUnitDetector::AccelUnitDetector(bool enabled, int samples, double gravity_m_s2)
    : enabled_(enabled), samples_needed_(std::max(1, samples)), gravity_m_s2_(gravity_m_s2), decided_(!enabled) {}

void AccelUnitDetector::add(const Eigen::Vector3d& accel) {
  if (decided_ || !accel.allFinite()) return;
  norm_sum_ += accel.norm();
  if (++count_ >= samples_needed_) decide();
}

void AccelUnitDetector::decide() {
  if (decided_) return;
  decided_ = true;
  if (!enabled_ || count_ == 0) return;
  mean_norm_ = norm_sum_ / count_;
  in_g_ = mean_norm_ > 0.0 && mean_norm_ < std::sqrt(gravity_m_s2_);
}

double AccelUnitDetector::scale() const { return in_g_ ? gravity_m_s2_ : 1.0; }

std::string AccelUnitDetector::message() const {
  if (!in_g_) return {};
  return "accelerometer reports in g (mean |a| of the first " + std::to_string(count_) +
         " samples = " + std::to_string(mean_norm_) + "); scaling by " + std::to_string(gravity_m_s2_) + " m/s^2";
}

}  // namespace farlio::fusion
