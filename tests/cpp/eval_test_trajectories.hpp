#pragma once
// Synthetic trajectories for the evaluation tests.
#include <cmath>
#include <cstdint>
#include <random>

#include "farlio/core/se3.hpp"
#include "farlio/core/trajectory.hpp"

namespace farlio::test {

inline constexpr std::int64_t kFramePeriod_ns = 100'000'000;  // 10 Hz

/// Random SE3 with rotation angle up to about pi and translation of scale `translation_m`.
inline SE3 random_se3(std::mt19937& rng, double translation_m) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return {q.normalized(), translation_m * Eigen::Vector3d(n(rng), n(rng), n(rng))};
}

/// A smooth 3-D loop (lissajous-like, heading along the tangent), `count` poses at 10 Hz.
inline Trajectory smooth_curve(std::size_t count, double radius_m = 50.0) {
  Trajectory t;
  constexpr double kAngularRate = 0.01;  // curve parameter per frame
  for (std::size_t k = 0; k < count; ++k) {
    const double s = kAngularRate * static_cast<double>(k);
    const Eigen::Vector3d p(radius_m * std::sin(s), 0.6 * radius_m * std::sin(2.0 * s),
                            0.05 * radius_m * std::sin(3.0 * s));
    const Eigen::Vector3d tangent(std::cos(s), 1.2 * std::cos(2.0 * s), 0.15 * std::cos(3.0 * s));
    const double yaw = std::atan2(tangent.y(), tangent.x());
    const double pitch = -std::atan2(tangent.z(), tangent.head<2>().norm());
    const Eigen::Quaterniond q =
        Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY());
    t.push_back(static_cast<std::int64_t>(k) * kFramePeriod_ns, SE3(q, p));
  }
  return t;
}

/// Straight line along x with `step_m` per frame.
inline Trajectory straight_line(std::size_t count, double step_m) {
  Trajectory t;
  for (std::size_t k = 0; k < count; ++k) {
    t.push_back(static_cast<std::int64_t>(k) * kFramePeriod_ns,
                SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(step_m * static_cast<double>(k), 0.0, 0.0)));
  }
  return t;
}

/// Rebuilds a trajectory from its relative motions, each passed through `modify` first:
/// out_0 = in_0, out_k = out_{k-1} * modify(in_{k-1}^-1 in_k).
template <class Modify>
Trajectory with_modified_increments(const Trajectory& in, Modify modify) {
  Trajectory out;
  if (in.empty()) return out;
  SE3 pose = in[0].pose;
  out.push_back(in[0].stamp_ns, pose);
  for (std::size_t k = 1; k < in.size(); ++k) {
    pose = pose * modify(in[k - 1].pose.inverse() * in[k].pose);
    out.push_back(in[k].stamp_ns, pose);
  }
  return out;
}

inline std::vector<SE3> poses_of(const Trajectory& t) {
  std::vector<SE3> out;
  for (const auto& p : t) out.push_back(p.pose);
  return out;
}

}  // namespace farlio::test
