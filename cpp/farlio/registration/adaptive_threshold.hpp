#pragma once
// KISS-ICP's adaptive threshold: sigma is the RMS of the model deviation (initial guess vs
// registered pose), where a rotation is turned into the displacement it causes at max range.
// FAR-LIO uses sigma for the correspondence distance (3 sigma) and the Cauchy scale (sigma/3).
#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"

namespace farlio::registration {

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
