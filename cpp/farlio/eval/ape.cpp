#include "farlio/eval/ape.hpp"

#include <string>

#include "farlio/core/error.hpp"
#include "farlio/eval/angles.hpp"

namespace farlio::eval {
namespace {

struct PerPairErrors {
  std::vector<double> translation_m;
  std::vector<double> rotation_deg;
};

PerPairErrors pair_errors(std::span<const SE3> estimate, std::span<const SE3> groundtruth) {
  PerPairErrors e;
  e.translation_m.reserve(estimate.size());
  e.rotation_deg.reserve(estimate.size());
  for (std::size_t k = 0; k < estimate.size(); ++k) {
    e.translation_m.push_back((groundtruth[k].translation() - estimate[k].translation()).norm());
    e.rotation_deg.push_back((groundtruth[k].inverse() * estimate[k]).angle_rad() * kDegreesPerRadian);
  }
  return e;
}

}  // namespace

ApeResult compute_ape(std::span<const SE3> estimate, std::span<const SE3> groundtruth, bool align_with_scale,
                      double min_spread_to_residual, ApeAlignment alignment) {
  if (estimate.size() != groundtruth.size()) {
    throw InputError("compute_ape: " + std::to_string(estimate.size()) + " estimate poses but " +
                     std::to_string(groundtruth.size()) + " ground-truth poses");
  }
  if (align_with_scale && alignment == ApeAlignment::kOrigin) {
    throw InputError("compute_ape: an alignment at the origin has no scale (align_with_scale and kOrigin)");
  }
  ApeResult r;
  if (estimate.empty()) return r;

  r.alignment = alignment == ApeAlignment::kOrigin
                    ? align_origin(estimate, groundtruth)
                    : align_poses(estimate, groundtruth, align_with_scale, min_spread_to_residual);
  r.aligned_estimate.reserve(estimate.size());
  for (const SE3& pose : estimate) r.aligned_estimate.push_back(r.alignment.apply(pose));

  const PerPairErrors raw = pair_errors(estimate, groundtruth);
  r.translation_raw_m = compute_stats(raw.translation_m);
  r.rotation_raw_deg = compute_stats(raw.rotation_deg);
  PerPairErrors aligned = pair_errors(r.aligned_estimate, groundtruth);
  r.translation_m = compute_stats(aligned.translation_m);
  r.rotation_deg = compute_stats(aligned.rotation_deg);
  r.translation_errors_m = std::move(aligned.translation_m);
  r.rotation_errors_deg = std::move(aligned.rotation_deg);
  return r;
}

}  // namespace farlio::eval
