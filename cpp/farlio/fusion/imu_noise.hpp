#pragma once
// The IMU's noise measured on its own samples, in any motion: the second difference of three
// evenly spaced samples, x[k+1] - 2 x[k] + x[k-1], removes the motion's level and slope and keeps
// six times the white noise's variance; what a vehicle's motion adds to it between samples is
// small at any IMU rate from 100 Hz (a car's yaw rate changes by 1e-4 rad/s in 10 ms; at 10 Hz a
// slalom's adds to the estimate, which then errs on the side of trusting the IMU less), while the
// vibration of a race car's body counts, as it should, as noise for the kinematic model. Per axis
// the median |second difference| over a batch of kBatchSamples samples gives the std of one sample
// (median / 0.6745 / sqrt(6): robust to a bump), a batch's estimate good to about 5 %; the
// estimate is the mean of the batches' variances over the last kMemoryBatches. Averaged over a
// filter step of n samples the input's std is that / sqrt(n). Measured on the simulator's IMUs
// (std over a 10 ms step): racetrack 0.007 rad/s and 0.18 m/s^2, urban 0.003 and 0.05, handheld
// 0.0036 and 0.057; a vibrating race car's (3e-3 rad/s/sqrt(Hz), 7e-2 m/s^2/sqrt(Hz) at 800 Hz)
// 0.030 and 0.70: its true values.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace farlio::fusion {

/// The noise of one IMU sample (std per axis) and the sample period it was measured at.
struct ImuNoise {
  Eigen::Vector3d gyro_std_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_std_m_s2 = Eigen::Vector3d::Zero();
  double sample_period_s = 0.0;
  /// The stds of the input averaged over a step of step_s (no less than one sample's when the IMU
  /// is slower than the step).
  [[nodiscard]] Eigen::Vector3d gyro_step_std_rad_s(double step_s) const;
  [[nodiscard]] Eigen::Vector3d accel_step_std_m_s2(double step_s) const;
};

class ImuNoiseMeter {
 public:
  /// One sample in SI units, in time order (an older one is ignored).
  void add(std::int64_t stamp_ns, const Eigen::Vector3d& gyro_rad_s, const Eigen::Vector3d& accel_m_s2);
  /// The estimate over the complete batches; nullopt before the first.
  [[nodiscard]] const std::optional<ImuNoise>& noise() const { return noise_; }
  /// Whether the last add completed a batch (a new estimate).
  [[nodiscard]] bool updated() const { return updated_; }

  /// Samples per estimate (1.25 s at 800 Hz, 5 s at 200 Hz) ...
  static constexpr std::size_t kBatchSamples = 1000;
  /// ... or those of kMaxBatch_s, kMinBatchSamples at least (a 10 Hz IMU's rate is known after 10 s).
  static constexpr double kMaxBatch_s = 10.0;
  static constexpr std::size_t kMinBatchSamples = 50;
  /// The batches' variances are averaged with an exponential memory of this many batches (the
  /// noise of a vehicle whose vibration changes with its speed follows within a minute at 200 Hz).
  static constexpr double kMemoryBatches = 10.0;
  /// Three samples count only when their two intervals differ by less than this fraction (a
  /// dropped sample would make the difference a slope's).
  static constexpr double kMaxIntervalMismatch = 0.1;

 private:
  struct Sample {
    std::int64_t stamp_ns = 0;
    Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
    Eigen::Vector3d accel = Eigen::Vector3d::Zero();
  };
  std::optional<Sample> previous_, before_previous_;
  std::vector<Eigen::Vector3d> gyro_differences_, accel_differences_;
  std::vector<double> intervals_s_;
  std::int64_t batch_start_ns_ = 0;
  std::optional<ImuNoise> noise_;
  Eigen::Vector3d gyro_variance_ = Eigen::Vector3d::Zero(), accel_variance_ = Eigen::Vector3d::Zero();
  std::size_t batches_ = 0;
  bool updated_ = false;
};

}  // namespace farlio::fusion
