#pragma once
// The gate every IMU sample passes before the fusion uses it. A single corrupt sample (a bit flip
// giving 1e30 m/s^2, a 1e4 m/s^2 spike, a 30 rad/s gyro glitch) integrated over one step moves
// the state by metres or degrees, so a sample is rejected when it is
//   - not finite,
//   - physically impossible: |a| over max_accel_m_s2 or |w| over max_gyro_rad_s (the full scale
//     of automotive and tactical MEMS parts is 16 g and 2000 deg/s),
//   - a spike: one axis further than spike_accel_m_s2 / spike_gyro_rad_s from the median of the
//     last spike_window_samples samples received (rejected ones included, so a real step in the
//     signal is accepted once it has lasted half the window),
// all of them fields of fusion.imu_gate.
// A rejected sample is left out; the buffer interpolates across it (imu_buffer.hpp).
#include <Eigen/Core>
#include <deque>
#include <string>

#include "farlio/core/config.hpp"
#include "farlio/core/types.hpp"

namespace farlio::fusion {

class ImuGate {
 public:
  explicit ImuGate(const FusionConfig& config);

  /// Empty when the sample may be used, else why it is rejected (the field and its value).
  /// accel_scale turns the raw accelerometer reading into m/s^2 (AccelUnitDetector).
  std::string check(const ImuSample& sample, double accel_scale);

 private:
  double max_accel_m_s2_, max_gyro_rad_s_, spike_accel_m_s2_, spike_gyro_rad_s_;
  std::size_t window_;
  std::deque<ImuSample> recent_;  ///< the last samples received, in m/s^2 and rad/s
};

}  // namespace farlio::fusion
