#pragma once
// KITTI-odometry style relative error over path-length segments.
//
// d_k = path length of the ground truth up to associated pose k (sum of position increments).
// For every first frame i in {0, step, 2 step, ...} and every segment length L, j is the first
// frame with d_j >= d_i + L (the pair is skipped when no such frame exists). With
//   E = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j)
// the segment errors are  t_err = |t(E)| / L  and  r_err = angle(E) / L.
// Reported: the mean over all (i, L) segments, translation in percent and rotation in degrees per
// 100 m, and the same mean per segment length.
//
// Segment lengths: {100, 200, ..., 800} m (KITTI) when the ground-truth path is at least
// kShortPathThreshold_m long, otherwise {10, 20, ..., 80} m; or the explicit list given.
// step_frames defaults to 1 (every frame is a first frame); the KITTI devkit uses 10.
#include <cstddef>
#include <span>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio::eval {

inline constexpr double kShortPathThreshold_m = 1000.0;
inline constexpr std::size_t kDefaultKittiStepFrames = 1;

/// {100, ..., 800} m.
std::vector<double> kitti_segment_lengths_m();
/// {10, ..., 80} m.
std::vector<double> short_segment_lengths_m();

struct KittiRpeOptions {
  std::size_t step_frames = kDefaultKittiStepFrames;
  std::vector<double> segment_lengths_m;  ///< empty: chosen by path length (see above)
  double short_path_threshold_m = kShortPathThreshold_m;
};

struct KittiLengthError {
  double length_m = 0.0;
  std::size_t segment_count = 0;
  double translation_pct = 0.0;        ///< mean t_err * 100 over segments of this length
  double rotation_deg_per_100m = 0.0;  ///< mean r_err in degrees per 100 m
};

struct KittiRpeResult {
  std::vector<double> segment_lengths_m;  ///< the lengths used
  std::size_t segment_count = 0;          ///< 0 when the path is shorter than every length
  double translation_pct = 0.0;           ///< mean over all segments (0 when segment_count == 0)
  double rotation_deg_per_100m = 0.0;
  std::vector<KittiLengthError> per_length;
};

/// Cumulative ground-truth path length d_k in metres (d_0 = 0).
std::vector<double> cumulative_path_length_m(std::span<const SE3> poses);

/// Sizes of `estimate` and `groundtruth` must match (throws InputError otherwise); step_frames >= 1.
KittiRpeResult compute_kitti_rpe(std::span<const SE3> estimate, std::span<const SE3> groundtruth,
                                 const KittiRpeOptions& options = {});

}  // namespace farlio::eval
