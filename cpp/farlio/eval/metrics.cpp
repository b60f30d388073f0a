#include "farlio/eval/metrics.hpp"

#include <string>

#include "farlio/core/error.hpp"

namespace farlio::eval {

EvaluationResult evaluate(const Trajectory& estimate, const Trajectory& groundtruth, const EvalOptions& options) {
  AssociatedPoses pairs = associate(estimate, groundtruth, options.association);
  if (pairs.size() < kMinAssociatedPoses) {
    throw InputError("evaluate: only " + std::to_string(pairs.size()) + " of " + std::to_string(estimate.size()) +
                     " estimate poses could be associated with the ground truth (need " +
                     std::to_string(kMinAssociatedPoses) + "); check the time stamps and max_time_diff_s");
  }
  EvaluationResult r;
  r.estimate_poses = estimate.size();
  r.groundtruth_poses = groundtruth.size();
  r.associated_poses = pairs.size();

  std::vector<std::int64_t> scan_stamps = options.scan_stamps_ns;
  if (scan_stamps.empty()) {
    for (const auto& p : groundtruth) scan_stamps.push_back(p.stamp_ns);
  }
  r.coverage = coverage(estimate, scan_stamps, options.association.max_time_diff_s);

  const std::vector<double> dist = cumulative_path_length_m(pairs.groundtruth);
  r.groundtruth_path_length_m = dist.back();
  r.ape = compute_ape(pairs.estimate, pairs.groundtruth, options.align_with_scale, options.min_spread_to_residual,
                      options.ape_alignment);
  r.kitti_rpe = compute_kitti_rpe(pairs.estimate, pairs.groundtruth, options.kitti);
  r.rpe = compute_delta_rpe(pairs.estimate, pairs.groundtruth, options.rpe);
  r.stamps_ns = std::move(pairs.stamps_ns);
  r.groundtruth = std::move(pairs.groundtruth);
  return r;
}

}  // namespace farlio::eval
