#include "farlio/fusion/gyro_unit_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "farlio/core/time.hpp"

namespace farlio::fusion {
namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;
/// Integrals kept for the comparison: the longest interval between two registered scans.
constexpr double kKeptIntegral_s = 5.0;
/// The regression decides once the slope's interval of this many standard errors lies above zero,
/// on one side of the midpoint between the units and around that unit's value, after
/// kMinRegressionIntervals intervals.
constexpr double kRegressionSigmas = 6.0;
constexpr int kMinRegressionIntervals = 8;
/// Beyond their standard error, the slope may miss its unit's value by this much (the gyro's
/// scale factor, the LiDAR's and the IMU's timing).
constexpr double kSlopeTolerance = 0.2;
/// The gyro's spread (per axis, in its unit) while the LiDAR does not turn, below which it reports
/// rad/s, and the samples that takes (see the header).
constexpr double kMaxQuietSpread = 0.02;
constexpr double kMinQuietSamples = 100.0;

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

}  // namespace

GyroUnitDetector::GyroUnitDetector(bool enabled, double min_rotation_rad, double min_rate_rad_s)
    : min_rotation_rad_(min_rotation_rad),
      min_rate_rad_s_(min_rate_rad_s),
      unit_(enabled ? GyroUnit::kUndecided : GyroUnit::kRadPerSecond) {}

void GyroUnitDetector::add_imu(const ImuSample& s) {
  if (decided() || !s.gyro_rad_s.allFinite()) return;
  if (!integrals_.empty() && s.stamp_ns <= integrals_.back().stamp_ns) return;
  if (last_) gyro_changed_ = gyro_changed_ || s.gyro_rad_s != last_->gyro_rad_s;
  if (integrals_.empty()) {
    integrals_.push_back({s.stamp_ns, Eigen::Vector3d::Zero()});
  } else {
    const double dt = ns_to_seconds(s.stamp_ns - integrals_.back().stamp_ns);
    integrals_.push_back({s.stamp_ns, integrals_.back().angle + 0.5 * dt * (s.gyro_rad_s + last_->gyro_rad_s)});
  }
  last_ = s;
  samples_.push_back(s);
  while (integrals_.size() > 2 && integrals_[1].stamp_ns < s.stamp_ns - seconds_to_ns(kKeptIntegral_s)) {
    integrals_.pop_front();
  }
  while (samples_.front().stamp_ns < s.stamp_ns - seconds_to_ns(kKeptIntegral_s)) samples_.pop_front();
}

void GyroUnitDetector::forget_samples() {
  integrals_.clear();
  samples_.clear();
}

void GyroUnitDetector::add_quiet_interval(std::int64_t start_ns, std::int64_t end_ns) {
  for (const ImuSample& s : samples_) {
    if (s.stamp_ns <= start_ns || s.stamp_ns > end_ns) continue;
    quiet_count_ += 1.0;
    quiet_sum_ += s.gyro_rad_s;
    quiet_sum_sq_ += s.gyro_rad_s.cwiseAbs2();
  }
  if (quiet_count_ < kMinQuietSamples) return;
  const Eigen::Vector3d mean = quiet_sum_ / quiet_count_;
  const Eigen::Vector3d spread = (quiet_sum_sq_ / quiet_count_ - mean.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  // a reading that never changes is a stuck gyro, not a quiet one
  if (gyro_changed_ && spread.maxCoeff() < kMaxQuietSpread) {
    unit_ = GyroUnit::kRadPerSecond;
    integrals_.clear();
    samples_.clear();
  }
}

std::optional<Eigen::Vector3d> GyroUnitDetector::integral_at(std::int64_t t) const {
  if (integrals_.empty() || t < integrals_.front().stamp_ns || t > integrals_.back().stamp_ns) return std::nullopt;
  for (std::size_t i = 1; i < integrals_.size(); ++i) {
    const Integral& a = integrals_[i - 1];
    const Integral& b = integrals_[i];
    if (t <= b.stamp_ns) {
      const double w = static_cast<double>(t - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
      return a.angle + w * (b.angle - a.angle);
    }
  }
  return integrals_.back().angle;  // t is the only stamp kept
}

std::optional<double> GyroUnitDetector::gyro_rotation(std::int64_t start_ns, std::int64_t end_ns) const {
  const auto a = integral_at(start_ns), b = integral_at(end_ns);
  if (!a || !b) return std::nullopt;
  return (*b - *a).norm();
}

bool GyroUnitDetector::turning(std::int64_t start_ns, std::int64_t end_ns) const {
  if (decided() || integrals_.empty()) return false;
  // the part of the interval the samples kept cover
  const std::int64_t start = std::max(start_ns, integrals_.front().stamp_ns);
  const std::int64_t end = std::min(end_ns, integrals_.back().stamp_ns);
  if (end <= start) return false;
  const auto rotation = gyro_rotation(start, end);
  return rotation && *rotation > min_rate_rad_s_ * ns_to_seconds(end - start);
}

void GyroUnitDetector::regress(const Eigen::Vector3d& gyro, const Eigen::Vector3d& lidar, double dt_s) {
  s_gg_ += gyro.squaredNorm();
  s_gl_ += gyro.dot(lidar);
  s_ll_ += lidar.squaredNorm();
  s_tt_ += dt_s * dt_s;
  s_gt_ += gyro * dt_s;
  s_lt_ += lidar * dt_s;
  ++regression_intervals_;
  if (regression_intervals_ < kMinRegressionIntervals) return;
  // eliminating the intercept c = (s_lt - k s_gt) / s_tt
  const double excitation = s_gg_ - s_gt_.squaredNorm() / s_tt_;  // the gyro's variation beyond a constant rate
  if (!(excitation > 0.0)) return;
  const double k = (s_gl_ - s_gt_.dot(s_lt_) / s_tt_) / excitation;
  const double residual = s_ll_ - s_lt_.squaredNorm() / s_tt_ - k * (s_gl_ - s_gt_.dot(s_lt_) / s_tt_);
  const double dof = 3.0 * regression_intervals_ - 4.0;
  const double k_std = std::sqrt(std::max(residual, 0.0) / dof / excitation);
  // k's interval: above zero (the LiDAR follows the gyro: not noise), on one side of the midpoint
  // between the units, and around that unit's value
  const double low = k - kRegressionSigmas * k_std, high = k + kRegressionSigmas * k_std;
  const double midpoint = 1.0 / std::sqrt(kDegreesPerRadian);
  const auto around = [&](double value) {
    return low <= value * (1.0 + kSlopeTolerance) && high >= value * (1.0 - kSlopeTolerance);
  };
  if (low > 0.0 && high < midpoint && around(1.0 / kDegreesPerRadian)) {
    unit_ = GyroUnit::kDegreesPerSecond;
  } else if (low > midpoint && around(1.0)) {
    unit_ = GyroUnit::kRadPerSecond;
  } else {
    return;
  }
  slope_ = k;
  slope_std_ = k_std;
  integrals_.clear();
}

void GyroUnitDetector::add_lidar_rotation(std::int64_t start_ns, std::int64_t end_ns,
                                          const Eigen::Vector3d& lidar_rotation) {
  if (decided() || end_ns <= start_ns) return;
  const auto a = integral_at(start_ns), b = integral_at(end_ns);
  if (!a || !b) return;
  const double dt_s = ns_to_seconds(end_ns - start_ns);
  regress(*b - *a, lidar_rotation, dt_s);
  if (decided()) return;
  const double gyro = (*b - *a).norm(), lidar_angle_rad = lidar_rotation.norm();
  if (lidar_angle_rad < min_rate_rad_s_ * dt_s) {
    add_quiet_interval(start_ns, end_ns);
    return;
  }
  gyro_sum_rad_ += gyro;
  lidar_sum_rad_ += lidar_angle_rad;
  ++intervals_;
  if (lidar_sum_rad_ < min_rotation_rad_) return;
  const double midpoint = std::sqrt(kDegreesPerRadian);  // between the two units on a log scale
  if (gyro_sum_rad_ > midpoint * lidar_sum_rad_) {
    unit_ = GyroUnit::kDegreesPerSecond;
  } else if (gyro_sum_rad_ * midpoint < lidar_sum_rad_) {
    unit_ = GyroUnit::kStuck;
  } else {
    unit_ = GyroUnit::kRadPerSecond;
  }
  integrals_.clear();
}

double GyroUnitDetector::scale() const { return unit_ == GyroUnit::kDegreesPerSecond ? 1.0 / kDegreesPerRadian : 1.0; }

std::string GyroUnitDetector::message() const {
  const std::string seen =
      slope_ != 0.0 ? "over " + std::to_string(regression_intervals_) + " scan intervals the LiDAR turned " +
                          number(slope_) + " +- " + number(slope_std_) + " times as far as the gyro integrated"
                    : "over " + std::to_string(intervals_) + " scan intervals the gyro integrated " +
                          number(gyro_sum_rad_) + " while the LiDAR turned " + number(lidar_sum_rad_) + " rad";
  const double ratio = slope_ != 0.0 ? 1.0 / slope_ : gyro_sum_rad_ / lidar_sum_rad_;
  switch (unit_) {
    case GyroUnit::kDegreesPerSecond:
      return "the gyro reports in deg/s (" + seen + ": the gyro reads " + number(ratio) +
             " times the rotation): scaling it by pi/180; the fusion starts again from the next LiDAR results";
    case GyroUnit::kStuck:
      if (!gyro_changed_) {
        return "the gyro is stuck: its reading " + number(last_->gyro_rad_s.x()) + ", " +
               number(last_->gyro_rad_s.y()) + ", " + number(last_->gyro_rad_s.z()) + " never changed (" + seen +
               "): the IMU is not used from now on (LiDAR-only)";
      }
      return "the gyro does not follow the LiDAR (" + seen +
             "): a dead gyro or a wrong unit; the IMU is not used "
             "from now on (LiDAR-only)";
    default: return {};
  }
}

std::string silent_accelerometer(const std::vector<Eigen::Vector3d>& samples) {
  if (samples.empty()) return {};
  double sum = 0.0;
  for (const auto& a : samples) sum += a.allFinite() ? a.norm() : 0.0;
  const double mean = sum / static_cast<double>(samples.size());
  if (mean >= kSilentAccelerometerNorm) return {};
  return "the accelerometer reads zero (mean |a| of the first " + std::to_string(samples.size()) +
         " samples = " + number(mean) + ", neither gravity in m/s^2 nor in g): the IMU is not used (LiDAR-only)";
}

}  // namespace farlio::fusion
