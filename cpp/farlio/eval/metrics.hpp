#pragma once
// Trajectory evaluation in one call: association, APE (aligned and raw), KITTI-style relative
// error, evo-style RPE and coverage. Definitions: docs/evaluation.md and the headers included.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "farlio/core/trajectory.hpp"
#include "farlio/eval/ape.hpp"
#include "farlio/eval/association.hpp"
#include "farlio/eval/rpe_delta.hpp"
#include "farlio/eval/rpe_kitti.hpp"

namespace farlio::eval {

/// Fewer associated pairs than this is an error (alignment and statistics need some support).
inline constexpr std::size_t kMinAssociatedPoses = 3;

struct EvalOptions {
  AssociationOptions association;
  bool align_with_scale = false;                             ///< Sim(3) instead of SE(3) alignment for the aligned APE
  ApeAlignment ape_alignment = ApeAlignment::kLeastSquares;  ///< every pair, or the first (ape.hpp)
  /// below this spread of the positions across an axis, in RMS residuals of the position fit, the
  /// rotation about it is taken from the orientations (align_poses)
  double min_spread_to_residual = kDefaultMinSpreadToResidual;
  KittiRpeOptions kitti;
  DeltaRpeOptions rpe;
  /// Stamps of the scans the estimate should cover (coverage); empty: the ground-truth stamps.
  std::vector<std::int64_t> scan_stamps_ns;
};

struct EvaluationResult {
  std::size_t estimate_poses = 0;
  std::size_t groundtruth_poses = 0;
  std::size_t associated_poses = 0;
  double coverage = 0.0;                   ///< fraction of scan stamps with an estimate pose
  double groundtruth_path_length_m = 0.0;  ///< along the associated ground-truth poses
  std::vector<std::int64_t> stamps_ns;     ///< stamps of the associated pairs
  std::vector<SE3> groundtruth;            ///< associated ground-truth poses
  ApeResult ape;                           ///< includes the aligned estimate poses
  KittiRpeResult kitti_rpe;
  DeltaRpeResult rpe;
};

/// Throws InputError for unordered trajectories or fewer than kMinAssociatedPoses pairs.
EvaluationResult evaluate(const Trajectory& estimate, const Trajectory& groundtruth, const EvalOptions& options = {});

}  // namespace farlio::eval
