#pragma once
// Detects an accelerometer that reports in g instead of m/s^2: the mean |a| of the first samples
// (taken at rest or in ordinary driving, where |a| is close to gravity) is compared with both
// hypotheses on a log scale, i.e. against the geometric midpoint sqrt(g) between 1 and g.
#include <Eigen/Core>
#include <string>

namespace farlio::fusion {

class AccelUnitDetector {
 public:
  /// enabled = false: always m/s^2.
  AccelUnitDetector(bool enabled, int samples, double gravity_m_s2);

  void add(const Eigen::Vector3d& accel);
  /// Decides now from the samples seen so far (no-op once decided).
  void decide();
  [[nodiscard]] bool decided() const { return decided_; }
  [[nodiscard]] bool in_g() const { return in_g_; }
  /// Factor that turns the raw accelerometer reading into m/s^2 (1 or g).
  [[nodiscard]] double scale() const;
  /// A message the caller can print once decided (empty if the unit is m/s^2).
  [[nodiscard]] std::string message() const;

 private:
  bool enabled_;
  int samples_needed_;
  double gravity_m_s2_;
  int count_ = 0;
  double norm_sum_ = 0.0;
  bool decided_ = false;
  bool in_g_ = false;
  double mean_norm_ = 0.0;
};

}  // namespace farlio::fusion
