#include "farlio/fusion/reference_angles.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "farlio/core/time.hpp"

namespace farlio::fusion {
namespace {
constexpr int kMinTaps = 1;

/// asin of the clamped argument; sets `saturated` when clamped.
double clamped_asin(double arg, double max_sin, bool& saturated) {
  if (std::abs(arg) > max_sin) saturated = true;
  return std::asin(std::clamp(arg, -max_sin, max_sin));
}
}  // namespace

Eigen::VectorXd hann_weights(int taps) {
  const int n = std::max(taps, kMinTaps);
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) {
    const double s = std::sin(std::numbers::pi * (i + 1) / (n + 1));
    w(i) = s * s;
  }
  return w / w.sum();
}

std::optional<ReferenceAngles> reference_angles_from_gravity(const Eigen::Vector3d& g_body_m_s2, double gravity_m_s2,
                                                             double max_sin) {
  if (!g_body_m_s2.allFinite() || !(gravity_m_s2 > 0.0)) return std::nullopt;
  ReferenceAngles out;
  out.pitch_rad = clamped_asin(g_body_m_s2.x() / gravity_m_s2, max_sin, out.saturated);
  const double roll_arg = -g_body_m_s2.y() / (gravity_m_s2 * std::cos(out.pitch_rad));
  out.roll_rad = clamped_asin(roll_arg, max_sin, out.saturated);
  if (!std::isfinite(out.roll_rad) || !std::isfinite(out.pitch_rad)) return std::nullopt;
  return out;
}

ReferenceAngleEstimator::ReferenceAngleEstimator(int taps, double gravity_m_s2, double max_sin)
    : weights_(hann_weights(taps % 2 == 1 ? taps : taps + 1)), gravity_m_s2_(gravity_m_s2), max_sin_(max_sin) {}

std::optional<ReferenceAngles> ReferenceAngleEstimator::push(std::int64_t stamp_ns, const Eigen::Vector3d& v_body_m_s,
                                                             const Eigen::Vector3d& accel_m_s2,
                                                             const Eigen::Vector3d& gyro_rad_s) {
  samples_.push_back({stamp_ns, v_body_m_s, accel_m_s2, gyro_rad_s});
  const std::size_t taps = static_cast<std::size_t>(weights_.size());
  const std::size_t needed = taps + 2;  // one extra on each side for the central difference
  while (samples_.size() > needed) samples_.pop_front();
  if (samples_.size() < needed) return std::nullopt;
  Eigen::Vector3d g_body = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < taps; ++i) {
    const Sample& prev = samples_[i];
    const Sample& cur = samples_[i + 1];
    const Sample& next = samples_[i + 2];
    const double span_s = ns_to_seconds(next.stamp_ns - prev.stamp_ns);
    const Eigen::Vector3d v_dot = (next.v - prev.v) / span_s;
    g_body += weights_(static_cast<Eigen::Index>(i)) * (v_dot - cur.a + cur.w.cross(cur.v));
  }
  auto angles = reference_angles_from_gravity(g_body, gravity_m_s2_, max_sin_);
  if (angles) angles->stamp_ns = samples_[taps / 2 + 1].stamp_ns;
  return angles;
}

}  // namespace farlio::fusion
