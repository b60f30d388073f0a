#include "farlio/fusion/imu_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "farlio/core/time.hpp"

namespace farlio::fusion {
namespace {

ImuReading reading_of(const ImuSample& s, bool in_gap) { return {s.gyro_rad_s, s.accel_m_s2, in_gap}; }
}  // namespace

ImuBuffer::ImuBuffer(double gap_limit_s, double retention_s)
    : gap_limit_ns_(seconds_to_ns(gap_limit_s)), retention_ns_(seconds_to_ns(retention_s)) {}

bool ImuBuffer::push(const ImuSample& sample) {
  if (!samples_.empty() && sample.stamp_ns < samples_.back().stamp_ns) return false;
  if (!samples_.empty() && sample.stamp_ns == samples_.back().stamp_ns) {
    samples_.back() = sample;  // a repeated stamp replaces the sample
    return true;
  }
  samples_.push_back(sample);
  return true;
}

ImuReading ImuBuffer::value(std::int64_t stamp_ns, bool from_left) const {
  if (samples_.empty()) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), true};
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), stamp_ns,
                                      [](std::int64_t t, const ImuSample& s) { return t < s.stamp_ns; });
  if (after == samples_.begin()) return reading_of(*after, after->stamp_ns - stamp_ns > gap_limit_ns_);
  const ImuSample& a = *std::prev(after);
  if (after == samples_.end()) return reading_of(a, stamp_ns - a.stamp_ns > gap_limit_ns_);
  const ImuSample& b = *after;
  if (b.stamp_ns - a.stamp_ns > gap_limit_ns_) return reading_of(a, true);
  if (a.stamp_ns == stamp_ns && from_left && after != std::next(samples_.begin())) {
    const ImuSample& before = *std::prev(after, 2);
    if (a.stamp_ns - before.stamp_ns > gap_limit_ns_) return reading_of(before, true);
  }
  const double s = static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  return {a.gyro_rad_s + s * (b.gyro_rad_s - a.gyro_rad_s), a.accel_m_s2 + s * (b.accel_m_s2 - a.accel_m_s2), false};
}

ImuReading ImuBuffer::at(std::int64_t stamp_ns) const { return value(stamp_ns, false); }

ImuReading ImuBuffer::mean(std::int64_t start_ns, std::int64_t end_ns) const {
  if (end_ns <= start_ns) return at(start_ns);
  // Breakpoints: the interval ends and every sample stamp inside; trapezoids in between.
  std::vector<std::int64_t> knots{start_ns};
  for (const ImuSample& s : samples_) {
    if (s.stamp_ns > start_ns && s.stamp_ns < end_ns) knots.push_back(s.stamp_ns);
  }
  knots.push_back(end_ns);
  ImuReading sum;
  for (std::size_t i = 0; i + 1 < knots.size(); ++i) {
    const ImuReading a = value(knots[i], false);
    const ImuReading b = value(knots[i + 1], true);
    const double w = static_cast<double>(knots[i + 1] - knots[i]) / static_cast<double>(end_ns - start_ns);
    sum.gyro_rad_s += 0.5 * w * (a.gyro_rad_s + b.gyro_rad_s);
    sum.accel += 0.5 * w * (a.accel + b.accel);
    sum.in_gap = sum.in_gap || a.in_gap || b.in_gap;
  }
  return sum;
}

void ImuBuffer::discard_before(std::int64_t stamp_ns) {
  const std::int64_t limit = stamp_ns - retention_ns_;
  while (samples_.size() > 1 && samples_[1].stamp_ns <= limit) samples_.pop_front();
}

}  // namespace farlio::fusion
