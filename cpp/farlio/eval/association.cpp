#include "farlio/eval/association.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/core/time.hpp"

namespace farlio::eval {
namespace {

/// Index of the stamp in sorted `stamps` nearest to t (earlier one on a tie); stamps non-empty.
std::size_t nearest_index(const std::vector<std::int64_t>& stamps, std::int64_t t) {
  const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
  if (it == stamps.begin()) return 0;
  if (it == stamps.end()) return stamps.size() - 1;
  const auto after = static_cast<std::size_t>(it - stamps.begin());
  return (*it - t) < (t - stamps[after - 1]) ? after : after - 1;
}

std::vector<std::int64_t> stamps_of(const Trajectory& trajectory) {
  std::vector<std::int64_t> stamps;
  stamps.reserve(trajectory.size());
  for (const auto& p : trajectory) stamps.push_back(p.stamp_ns);
  return stamps;
}

void require_time_ordered(const Trajectory& trajectory, const char* name) {
  if (!trajectory.is_time_ordered()) {
    throw InputError(std::string("associate: the ") + name + " trajectory is not strictly time ordered");
  }
}

/// Step 1 of the interpolation rule: ground truth interpolated at t over a short enough gap.
std::optional<SE3> interpolate_within_gap(const Trajectory& gt, const std::vector<std::int64_t>& gt_stamps,
                                          std::int64_t t, std::int64_t max_gap_ns) {
  if (t < gt_stamps.front() || t > gt_stamps.back()) return std::nullopt;
  const auto it = std::lower_bound(gt_stamps.begin(), gt_stamps.end(), t);
  const auto b = static_cast<std::size_t>(it - gt_stamps.begin());
  if (gt_stamps[b] == t) return gt[b].pose;
  if (gt_stamps[b] - gt_stamps[b - 1] > max_gap_ns) return std::nullopt;
  const double s = static_cast<double>(t - gt_stamps[b - 1]) / static_cast<double>(gt_stamps[b] - gt_stamps[b - 1]);
  return interpolate(gt[b - 1].pose, gt[b].pose, s);
}

}  // namespace

AssociatedPoses associate(const Trajectory& estimate, const Trajectory& groundtruth,
                          const AssociationOptions& options) {
  require_time_ordered(estimate, "estimate");
  require_time_ordered(groundtruth, "ground-truth");
  AssociatedPoses out;
  if (estimate.empty() || groundtruth.empty()) return out;
  const std::vector<std::int64_t> gt_stamps = stamps_of(groundtruth);
  const std::int64_t max_diff_ns = seconds_to_ns(options.max_time_diff_s);
  const std::int64_t max_gap_ns = seconds_to_ns(options.max_gt_gap_s);

  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const std::int64_t t = estimate[i].stamp_ns;
    std::optional<SE3> gt_pose;
    if (options.mode == AssociationMode::kInterpolate) {
      gt_pose = interpolate_within_gap(groundtruth, gt_stamps, t, max_gap_ns);
    }
    if (!gt_pose) {
      const std::size_t k = nearest_index(gt_stamps, t);
      if (std::abs(gt_stamps[k] - t) <= max_diff_ns) gt_pose = groundtruth[k].pose;
    }
    if (!gt_pose) continue;
    out.stamps_ns.push_back(t);
    out.estimate_indices.push_back(i);
    out.estimate.push_back(estimate[i].pose);
    out.groundtruth.push_back(*gt_pose);
  }
  return out;
}

double coverage(const Trajectory& estimate, std::span<const std::int64_t> scan_stamps_ns, double max_time_diff_s) {
  if (scan_stamps_ns.empty()) return 0.0;
  if (estimate.empty()) return 0.0;
  std::vector<std::int64_t> est_stamps = stamps_of(estimate);
  std::sort(est_stamps.begin(), est_stamps.end());
  const std::int64_t max_diff_ns = seconds_to_ns(max_time_diff_s);
  std::size_t covered = 0;
  for (const std::int64_t t : scan_stamps_ns) {
    if (std::abs(est_stamps[nearest_index(est_stamps, t)] - t) <= max_diff_ns) ++covered;
  }
  return static_cast<double>(covered) / static_cast<double>(scan_stamps_ns.size());
}

}  // namespace farlio::eval
