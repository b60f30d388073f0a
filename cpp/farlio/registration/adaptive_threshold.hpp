#pragma once
// KISS-ICP's adaptive threshold: sigma is the RMS of the model deviation (initial guess vs
// registered pose), where a rotation is turned into the displacement it causes at max range.
// FAR-LIO uses sigma for the correspondence distance (3 sigma) and the Cauchy scale (sigma/3).
#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"

namespace farlio::registration {

/// The model error of a deviation (initial guess^-1 * registered, or between two motions): its
/// translation plus the displacement its rotation causes at config.max_range_m (m).
double model_error_m(const SE3& deviation, const ThresholdConfig& config);

/// Sigma of a registration without a motion model (the first one, whose guess assumes rest): its
/// correspondences reach max_threshold_m (3 sigma).
inline double sigma_without_motion_model_m(const ThresholdConfig& config) { return config.max_threshold_m / 3.0; }

class AdaptiveThreshold {
 public:
  explicit AdaptiveThreshold(const ThresholdConfig& config);
  /// Current sigma in metres (capped at max_threshold_m).
  [[nodiscard]] double sigma_m() const;
  /// Adds a sample: deviation = initial_guess^-1 * registered. Returns the model error (m).
  double update(const SE3& deviation);

 private:
  ThresholdConfig config_;
  double sum_squared_error_;
  double num_samples_;
};

}  // namespace farlio::registration
