#pragma once
// Detects a gyro that reports in deg/s instead of rad/s, or that is stuck, against the LiDAR: the
// rotation the gyro integrates between two registered scans is compared with the rotation
// between their poses, in two ways.
//   Turns: only intervals in which the LiDAR turned faster than a minimum rate count (so that a
//   gyro bias at rest weighs nothing). Once the LiDAR's rotation over those intervals reaches
//   min_rotation_rad, the ratio gyro / LiDAR decides on a log scale, as the accelerometer's unit
//   (accel_unit_detector.hpp): near 1 rad/s, near 180/pi deg/s (the midpoint is sqrt(180/pi) =
//   7.6); below 1/7.6 the gyro does not follow the LiDAR at all (stuck: its reading never
//   changes, or dead) and is not to be used.
//   Small rotations: over every interval, the LiDAR's rotation vector is regressed on the gyro's,
//   with a constant rate (the gyro's bias) as the intercept: r_lidar = k r_gyro + c dt. The
//   lane keeping, the road's grade and the body's sway of a straight drive are enough for k to
//   come out near 1 (rad/s) or near pi/180 (deg/s) well before the first turn; k is taken once its
//   interval of several standard errors lies above zero (the LiDAR follows the gyro: the gyro's
//   readings are not its noise alone) and around one unit's value.
//   Noise while the LiDAR does not turn: the gyro's readings spread by its noise about its bias.
//   A spread below kMaxQuietSpread (0.02 in the gyro's unit) over kMinQuietSamples samples is a
//   rad/s gyro: in deg/s it would be 3.5e-4 rad/s a sample, a navigation-grade gyro's, where a
//   MEMS gyro spreads by 1e-3..1e-2 rad/s (0.06..0.6 deg/s). A larger spread (vibration, a
//   deg/s gyro) decides nothing.
// The detector also tells whether a scan's gyro rotation is large enough that, while the unit is
// undecided, the fusion's guess (which a deg/s gyro would ruin) should not be used for it.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/types.hpp"

namespace farlio::fusion {

/// kStuck: the gyro turns far less than the LiDAR (a reading that never changes, a dead gyro).
enum class GyroUnit { kUndecided, kRadPerSecond, kDegreesPerSecond, kStuck };

class GyroUnitDetector {
 public:
  /// enabled = false: rad/s from the start. min_rate_rad_s: intervals in which the LiDAR turned
  /// slower than this are not compared.
  GyroUnitDetector(bool enabled, double min_rotation_rad, double min_rate_rad_s);

  /// A raw sample (in time order; an older one is ignored).
  void add_imu(const ImuSample& sample);
  /// Starts the gyro integral again (after a jump of the IMU clock); the sums are kept.
  void forget_samples();
  /// The norm of the gyro's integral over [start_ns, end_ns] (rad in the gyro's own unit);
  /// nullopt when the samples kept do not cover the interval.
  [[nodiscard]] std::optional<double> gyro_rotation(std::int64_t start_ns, std::int64_t end_ns) const;
  /// The LiDAR's rotation (rotation vector, body frame) between two scan ends; decides once
  /// enough rotation was compared.
  void add_lidar_rotation(std::int64_t start_ns, std::int64_t end_ns, const Eigen::Vector3d& lidar_rotation);

  [[nodiscard]] GyroUnit unit() const { return unit_; }
  [[nodiscard]] bool decided() const { return unit_ != GyroUnit::kUndecided; }
  /// Factor that turns the raw gyro reading into rad/s (pi/180 for deg/s, else 1).
  [[nodiscard]] double scale() const;
  /// What was found, for a warning (empty for rad/s).
  [[nodiscard]] std::string message() const;
  /// While undecided: whether the gyro turned faster than the minimum rate over the interval
  /// (so a guess predicted from it may be off by the unit's factor).
  [[nodiscard]] bool turning(std::int64_t start_ns, std::int64_t end_ns) const;

 private:
  struct Integral {
    std::int64_t stamp_ns;
    Eigen::Vector3d angle;  ///< integral of the gyro since the first sample kept
  };
  [[nodiscard]] std::optional<Eigen::Vector3d> integral_at(std::int64_t stamp_ns) const;

  double min_rotation_rad_;
  double min_rate_rad_s_;
  GyroUnit unit_;
  std::deque<Integral> integrals_;
  std::optional<ImuSample> last_;
  bool gyro_changed_ = false;
  /// The regression of the LiDAR's rotations on the gyro's: decides when k is clear.
  void regress(const Eigen::Vector3d& gyro, const Eigen::Vector3d& lidar, double dt_s);
  /// The gyro's samples over an interval in which the LiDAR did not turn: decides rad/s when they
  /// spread by a MEMS gyro's noise in rad/s.
  void add_quiet_interval(std::int64_t start_ns, std::int64_t end_ns);

  double gyro_sum_rad_ = 0.0, lidar_sum_rad_ = 0.0;
  int intervals_ = 0;
  // sums of the regression r_lidar = k r_gyro + c dt over the intervals
  double s_gg_ = 0.0, s_gl_ = 0.0, s_ll_ = 0.0, s_tt_ = 0.0;
  Eigen::Vector3d s_gt_ = Eigen::Vector3d::Zero(), s_lt_ = Eigen::Vector3d::Zero();
  int regression_intervals_ = 0;
  double slope_ = 0.0, slope_std_ = 0.0;  ///< k and its standard error when it decided
  std::deque<ImuSample> samples_;         ///< raw, the last kKeptIntegral_s, for the quiet intervals
  // the samples of the quiet intervals: count, sum, sum of squares (per axis)
  double quiet_count_ = 0.0;
  Eigen::Vector3d quiet_sum_ = Eigen::Vector3d::Zero(), quiet_sum_sq_ = Eigen::Vector3d::Zero();
};

/// Mean |accel| below this (in m/s^2 or in g) is no accelerometer at all: it reads zero.
inline constexpr double kSilentAccelerometerNorm = 0.1;
/// A warning when the mean |accel| of `samples` (the first ones of a recording) is below
/// kSilentAccelerometerNorm: the accelerometer reads zero and the IMU cannot be used; empty
/// otherwise (also for no samples).
[[nodiscard]] std::string silent_accelerometer(const std::vector<Eigen::Vector3d>& samples);

}  // namespace farlio::fusion
