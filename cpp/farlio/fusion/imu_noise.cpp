#include "farlio/fusion/imu_noise.hpp"

#include <algorithm>
#include <cmath>

#include "farlio/core/time.hpp"
#include "farlio/fusion/axis_median.hpp"

namespace farlio::fusion {
namespace {

/// Median |x| of a normal variable / its std.
constexpr double kMedianAbsoluteOfNormal = 0.6745;
/// The variance of a second difference of white noise, in the samples' variance.
constexpr double kSecondDifferenceVariance = 6.0;

double median(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The std of one sample per axis from the second differences.
Eigen::Vector3d sample_std(const std::vector<Eigen::Vector3d>& differences) {
  const Eigen::Vector3d median_abs =
      axis_median(differences, [](const Eigen::Vector3d& d) -> Eigen::Vector3d { return d.cwiseAbs(); });
  return median_abs / kMedianAbsoluteOfNormal / std::sqrt(kSecondDifferenceVariance);
}

/// The std of the mean of a step's samples: one sample's / sqrt(samples a step), never below one.
double step_factor(double sample_period_s, double step_s) {
  if (!(sample_period_s > 0.0) || !(step_s > 0.0)) return 1.0;
  return std::sqrt(std::min(1.0, sample_period_s / step_s));
}

}  // namespace

Eigen::Vector3d ImuNoise::gyro_step_std_rad_s(double step_s) const {
  return gyro_std_rad_s * step_factor(sample_period_s, step_s);
}

Eigen::Vector3d ImuNoise::accel_step_std_m_s2(double step_s) const {
  return accel_std_m_s2 * step_factor(sample_period_s, step_s);
}

void ImuNoiseMeter::add(std::int64_t stamp_ns, const Eigen::Vector3d& gyro_rad_s, const Eigen::Vector3d& accel_m_s2) {
  updated_ = false;
  if (previous_ && stamp_ns <= previous_->stamp_ns) return;
  if (!gyro_rad_s.allFinite() || !accel_m_s2.allFinite()) return;
  const Sample sample{stamp_ns, gyro_rad_s, accel_m_s2};
  if (previous_ && before_previous_) {
    const double first_s = ns_to_seconds(previous_->stamp_ns - before_previous_->stamp_ns);
    const double second_s = ns_to_seconds(stamp_ns - previous_->stamp_ns);
    if (std::abs(second_s - first_s) <= kMaxIntervalMismatch * std::max(first_s, second_s)) {
      if (gyro_differences_.empty()) batch_start_ns_ = stamp_ns;
      gyro_differences_.push_back(sample.gyro - 2.0 * previous_->gyro + before_previous_->gyro);
      accel_differences_.push_back(sample.accel - 2.0 * previous_->accel + before_previous_->accel);
      intervals_s_.push_back(second_s);
    }
  }
  before_previous_ = previous_;
  previous_ = sample;
  const bool long_enough =
      gyro_differences_.size() >= kMinBatchSamples && ns_to_seconds(stamp_ns - batch_start_ns_) >= kMaxBatch_s;
  if (gyro_differences_.size() < kBatchSamples && !long_enough) return;
  ++batches_;
  const double weight = 1.0 / std::min(static_cast<double>(batches_), kMemoryBatches);
  gyro_variance_ += weight * (sample_std(gyro_differences_).cwiseAbs2() - gyro_variance_);
  accel_variance_ += weight * (sample_std(accel_differences_).cwiseAbs2() - accel_variance_);
  noise_ = ImuNoise{gyro_variance_.cwiseSqrt(), accel_variance_.cwiseSqrt(), median(intervals_s_)};
  gyro_differences_.clear();
  accel_differences_.clear();
  intervals_s_.clear();
  updated_ = true;
}

}  // namespace farlio::fusion
