#pragma once
// Pairing an estimated trajectory with ground truth by time stamp.
//
// Rule (AssociationMode::kInterpolate, the default): for every estimate pose at stamp t,
//   1. if ground truth has poses a, b with a.stamp <= t <= b.stamp and b.stamp - a.stamp <=
//      max_gt_gap_s, the ground truth pose is the geodesic interpolation between a and b at t
//      (exactly a's pose when t == a.stamp);
//   2. otherwise (t outside the ground-truth span, or inside a gap longer than max_gt_gap_s)
//      the ground-truth pose nearest in time is used if |stamp - t| <= max_time_diff_s;
//   3. otherwise the estimate pose is left out.
// AssociationMode::kNearest skips step 1: every estimate pose takes the nearest ground-truth pose
// within max_time_diff_s (ties go to the earlier one). Both trajectories must be time ordered.
//
// Coverage: the fraction of reference scan stamps that have an estimate pose within
// max_time_diff_s (the scan stamps default to the ground-truth stamps).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/core/trajectory.hpp"

namespace farlio::eval {

inline constexpr double kDefaultMaxTimeDiff_s = 0.01;
inline constexpr double kDefaultMaxGroundTruthGap_s = 0.5;

enum class AssociationMode { kInterpolate, kNearest };

struct AssociationOptions {
  AssociationMode mode = AssociationMode::kInterpolate;
  double max_time_diff_s = kDefaultMaxTimeDiff_s;     ///< tolerance of a nearest-stamp match
  double max_gt_gap_s = kDefaultMaxGroundTruthGap_s;  ///< longest ground-truth gap interpolated over
};

/// Associated pose pairs, in estimate order; index k of every vector refers to the same pair.
struct AssociatedPoses {
  std::vector<std::int64_t> stamps_ns;        ///< the estimate stamps
  std::vector<std::size_t> estimate_indices;  ///< index into the estimate trajectory
  std::vector<SE3> estimate;
  std::vector<SE3> groundtruth;
  [[nodiscard]] std::size_t size() const { return stamps_ns.size(); }
};

/// Throws InputError when either trajectory is not strictly time ordered.
AssociatedPoses associate(const Trajectory& estimate, const Trajectory& groundtruth,
                          const AssociationOptions& options = {});

/// Fraction in [0, 1] of `scan_stamps_ns` having an estimate stamp within max_time_diff_s;
/// 0 for an empty stamp list.
double coverage(const Trajectory& estimate, std::span<const std::int64_t> scan_stamps_ns, double max_time_diff_s);

}  // namespace farlio::eval
