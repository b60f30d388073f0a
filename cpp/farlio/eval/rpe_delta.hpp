#pragma once
// Relative pose error between pose pairs a fixed distance apart, as defined by evo's RPE:
//   E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j)     Q: ground truth, P: estimate
// translation error |t(E_ij)| (metres), rotation error angle(E_ij) (degrees).
//
// Pair selection over the associated poses (d_k: cumulative path length of the poses the pairs are
// taken from, see `pairs_from_groundtruth`):
//   frames, consecutive:  ids 0, delta, 2 delta, ...; pairs (ids[n], ids[n+1])
//   frames, all pairs:    (i, i + delta) for every i with i + delta < N
//   metres, consecutive:  ids starts at 0; the next id is the first k whose path length since the
//                         last id is >= delta; pairs (ids[n], ids[n+1])
//   metres, all pairs:    for every i < N - 1, j = the k > i minimising |d_k - d_i - delta| (first
//                         one on a tie); kept if that difference is <= rel_delta_tol * delta
// These match evo_rpe's --delta/--delta_unit f|m/--all_pairs; evo measures metres along the
// estimate unless --pairs_from_reference is given, while we default to the ground truth.
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/eval/error_stats.hpp"

namespace farlio::eval {

inline constexpr double kDefaultRpeDelta = 1.0;
inline constexpr double kDefaultRelativeDeltaTolerance = 0.1;

enum class DeltaUnit { kFrames, kMeters };

struct DeltaRpeOptions {
  double delta = kDefaultRpeDelta;  ///< frames (a whole number >= 1) or metres (> 0)
  DeltaUnit unit = DeltaUnit::kFrames;
  bool all_pairs = false;
  double rel_delta_tol = kDefaultRelativeDeltaTolerance;  ///< metres, all pairs only
  bool pairs_from_groundtruth = true;                     ///< measure metres along the ground truth (evo: estimate)
};

using IndexPair = std::pair<std::size_t, std::size_t>;

/// The pairs (i, j), i < j, selected from `poses` by the rule above; throws InputError on a bad delta.
std::vector<IndexPair> select_rpe_pairs(std::span<const SE3> poses, const DeltaRpeOptions& options);

struct DeltaRpeResult {
  std::vector<IndexPair> pairs;
  ErrorStats translation_m;
  ErrorStats rotation_deg;
  std::vector<double> translation_errors_m;  ///< per pair
};

DeltaRpeResult compute_delta_rpe(std::span<const SE3> estimate, std::span<const SE3> groundtruth,
                                 const DeltaRpeOptions& options = {});

}  // namespace farlio::eval
