#pragma once
// Time-ordered raw IMU samples as a piecewise-linear signal: the EKF reads the input at step
// boundaries and its mean over a step. Across a gap longer than the limit (or beyond the newest
// sample by more than the limit) the last input before the gap is held and the read is flagged.
#include <cstdint>
#include <deque>

#include "farlio/core/types.hpp"

namespace farlio::fusion {

struct ImuReading {
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< in the IMU's own unit (see AccelUnitDetector)
  bool in_gap = false;                              ///< the value is held across a gap
};

class ImuBuffer {
 public:
  ImuBuffer(double gap_limit_s, double retention_s);

  /// Appends a sample; false (sample dropped) if it is older than the newest one.
  bool push(const ImuSample& sample);
  [[nodiscard]] bool empty() const { return samples_.empty(); }
  [[nodiscard]] const ImuSample& newest() const { return samples_.back(); }
  [[nodiscard]] const ImuSample& oldest() const { return samples_.front(); }

  /// The signal at stamp_ns (linear interpolation; held before the first and after the last sample).
  [[nodiscard]] ImuReading at(std::int64_t stamp_ns) const;
  /// The mean of the signal over [start_ns, end_ns] (exact for the piecewise-linear signal).
  [[nodiscard]] ImuReading mean(std::int64_t start_ns, std::int64_t end_ns) const;
  /// Forgets samples older than retention before stamp_ns (keeps one before it).
  void discard_before(std::int64_t stamp_ns);

 private:
  /// Value at t; from_left selects the left limit at a held gap's end.
  [[nodiscard]] ImuReading value(std::int64_t stamp_ns, bool from_left) const;

  std::int64_t gap_limit_ns_;
  std::int64_t retention_ns_;
  std::deque<ImuSample> samples_;
};

}  // namespace farlio::fusion
