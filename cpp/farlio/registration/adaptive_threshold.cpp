#include "farlio/registration/adaptive_threshold.hpp"

#include <algorithm>
#include <cmath>

namespace farlio::registration {

double model_error_m(const SE3& deviation, const ThresholdConfig& config) {
  return deviation.translation().norm() + 2.0 * config.max_range_m * std::sin(0.5 * deviation.angle_rad());
}

AdaptiveThreshold::AdaptiveThreshold(const ThresholdConfig& config)
    // The initial threshold counts as one sample (as the reference does).
    : config_(config), sum_squared_error_(config.initial_threshold_m * config.initial_threshold_m), num_samples_(1.0) {}

double AdaptiveThreshold::sigma_m() const {
  return std::min(config_.max_threshold_m, std::sqrt(sum_squared_error_ / num_samples_));
}

double AdaptiveThreshold::update(const SE3& deviation) {
  const double error = model_error_m(deviation, config_);
  if (error > config_.min_motion_m) {
    sum_squared_error_ += error * error;
    num_samples_ += 1.0;
  }
  return error;
}

}  // namespace farlio::registration
