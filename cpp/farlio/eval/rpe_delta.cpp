#include "farlio/eval/rpe_delta.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/eval/angles.hpp"
#include "farlio/eval/rpe_kitti.hpp"

namespace farlio::eval {
namespace {

std::vector<IndexPair> consecutive(const std::vector<std::size_t>& ids) {
  std::vector<IndexPair> pairs;
  for (std::size_t n = 1; n < ids.size(); ++n) pairs.emplace_back(ids[n - 1], ids[n]);
  return pairs;
}

std::vector<IndexPair> pairs_by_frames(std::size_t count, std::size_t delta, bool all_pairs) {
  if (all_pairs) {
    std::vector<IndexPair> pairs;
    for (std::size_t i = 0; i + delta < count; ++i) pairs.emplace_back(i, i + delta);
    return pairs;
  }
  std::vector<std::size_t> ids;
  for (std::size_t i = 0; i < count; i += delta) ids.push_back(i);
  return consecutive(ids);
}

std::vector<IndexPair> pairs_by_path(std::span<const SE3> poses, double delta_m, double tol_m, bool all_pairs) {
  if (poses.empty()) return {};
  if (all_pairs) {
    const std::vector<double> d = cumulative_path_length_m(poses);
    std::vector<IndexPair> pairs;
    for (std::size_t i = 0; i + 1 < d.size(); ++i) {
      // d is non-decreasing: the minimiser is the first k >= i + 1 with d_k >= d_i + delta, or
      // the first k holding the largest value below it (the earlier one on a tie).
      const auto first = d.begin() + static_cast<std::ptrdiff_t>(i + 1);
      const auto above = std::lower_bound(first, d.end(), d[i] + delta_m);
      const auto miss = [&](auto it) { return std::abs(*it - d[i] - delta_m); };
      auto best = above;
      if (above != first) {
        const auto below = std::lower_bound(first, above, *(above - 1));
        if (above == d.end() || miss(below) <= miss(above)) best = below;
      }
      if (miss(best) <= tol_m) pairs.emplace_back(i, static_cast<std::size_t>(best - d.begin()));
    }
    return pairs;
  }
  std::vector<std::size_t> ids{0};
  double since_last_m = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    since_last_m += (poses[k].translation() - poses[k - 1].translation()).norm();
    if (since_last_m >= delta_m) {
      ids.push_back(k);
      since_last_m = 0.0;
    }
  }
  return consecutive(ids);
}

}  // namespace

std::vector<IndexPair> select_rpe_pairs(std::span<const SE3> poses, const DeltaRpeOptions& options) {
  if (!(options.delta > 0.0)) throw InputError("RPE delta must be > 0, got " + std::to_string(options.delta));
  if (options.unit == DeltaUnit::kFrames) {
    if (options.delta != std::floor(options.delta)) {
      throw InputError("RPE delta in frames must be a whole number, got " + std::to_string(options.delta));
    }
    return pairs_by_frames(poses.size(), static_cast<std::size_t>(options.delta), options.all_pairs);
  }
  return pairs_by_path(poses, options.delta, options.delta * options.rel_delta_tol, options.all_pairs);
}

DeltaRpeResult compute_delta_rpe(std::span<const SE3> estimate, std::span<const SE3> groundtruth,
                                 const DeltaRpeOptions& options) {
  if (estimate.size() != groundtruth.size()) {
    throw InputError("compute_delta_rpe: " + std::to_string(estimate.size()) + " estimate poses but " +
                     std::to_string(groundtruth.size()) + " ground-truth poses");
  }
  DeltaRpeResult r;
  r.pairs = select_rpe_pairs(options.pairs_from_groundtruth ? groundtruth : estimate, options);
  std::vector<double> rotation_deg;
  r.translation_errors_m.reserve(r.pairs.size());
  rotation_deg.reserve(r.pairs.size());
  for (const auto& [i, j] : r.pairs) {
    const SE3 error = (groundtruth[i].inverse() * groundtruth[j]).inverse() * (estimate[i].inverse() * estimate[j]);
    r.translation_errors_m.push_back(error.translation().norm());
    rotation_deg.push_back(error.angle_rad() * kDegreesPerRadian);
  }
  r.translation_m = compute_stats(r.translation_errors_m);
  r.rotation_deg = compute_stats(rotation_deg);
  return r;
}

}  // namespace farlio::eval
