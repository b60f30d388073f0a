#include "farlio/core/trajectory.hpp"

#include <algorithm>

namespace farlio {

bool Trajectory::is_time_ordered() const {
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    if (poses_[i].stamp_ns <= poses_[i - 1].stamp_ns) return false;
  }
  return true;
}

std::optional<SE3> Trajectory::interpolate_at(std::int64_t stamp_ns) const {
  if (poses_.empty() || stamp_ns < poses_.front().stamp_ns || stamp_ns > poses_.back().stamp_ns) {
    return std::nullopt;
  }
  auto it = std::lower_bound(poses_.begin(), poses_.end(), stamp_ns,
                             [](const StampedPose& p, std::int64_t t) { return p.stamp_ns < t; });
  if (it->stamp_ns == stamp_ns) return it->pose;
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double s = static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  return interpolate(a.pose, b.pose, s);
}

Trajectory Trajectory::transformed(const SE3& extrinsic) const {
  Trajectory out;
  out.poses_.reserve(poses_.size());
  for (const auto& p : poses_) out.poses_.push_back({p.stamp_ns, p.pose * extrinsic});
  return out;
}

Trajectory Trajectory::between(std::int64_t begin_ns, std::int64_t end_ns) const {
  Trajectory out;
  for (const auto& p : poses_) {
    if (p.stamp_ns >= begin_ns && p.stamp_ns <= end_ns) out.push_back(p.stamp_ns, p.pose);
  }
  return out;
}

double Trajectory::path_length_m() const {
  double len = 0.0;
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    len += (poses_[i].pose.translation() - poses_[i - 1].pose.translation()).norm();
  }
  return len;
}

}  // namespace farlio
