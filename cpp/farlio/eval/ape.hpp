#pragma once
// Absolute pose error (APE / ATE) of associated pose pairs.
//   aligned: estimate poses mapped by the alignment of the estimate onto the ground truth
//            (align_poses: Umeyama on the positions, orientations where the positions leave the
//            rotation free; or align_origin: the first poses made one); raw: the estimate as
//            given (same world frame assumed).
//   translation error_k = | t(gt_k) - t(est_k) |            (metres)
//   rotation error_k    = angle( R(gt_k)^T R(est_k) )        (degrees)
#include <span>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/eval/alignment.hpp"
#include "farlio/eval/error_stats.hpp"

namespace farlio::eval {

struct ApeResult {
  Alignment alignment;                       ///< estimate -> ground-truth frame
  ErrorStats translation_m;                  ///< after alignment
  ErrorStats rotation_deg;                   ///< after alignment
  ErrorStats translation_raw_m;              ///< without alignment
  ErrorStats rotation_raw_deg;               ///< without alignment
  std::vector<double> translation_errors_m;  ///< per pair, after alignment
  std::vector<double> rotation_errors_deg;   ///< per pair, after alignment
  std::vector<SE3> aligned_estimate;         ///< the estimate poses after alignment
};

/// How the estimate is aligned onto the ground truth.
enum class ApeAlignment {
  kLeastSquares,  ///< align_poses over every pair (evo_ape --align)
  kOrigin,        ///< align_origin: the drift from the first pair (evo_ape --align_origin)
};

/// `estimate[k]` and `groundtruth[k]` are a pair; sizes must match (throws InputError otherwise).
/// align_with_scale and min_spread_to_residual: as align_poses; a scale with kOrigin is an InputError.
ApeResult compute_ape(std::span<const SE3> estimate, std::span<const SE3> groundtruth, bool align_with_scale = false,
                      double min_spread_to_residual = kDefaultMinSpreadToResidual,
                      ApeAlignment alignment = ApeAlignment::kLeastSquares);

}  // namespace farlio::eval
