#include "farlio/eval/rpe_kitti.hpp"

#include <algorithm>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/eval/angles.hpp"

namespace farlio::eval {
namespace {

constexpr double kPercent = 100.0;
constexpr double kPerHundredMetres = 100.0;
constexpr double kKittiFirstLength_m = 100.0;
constexpr double kShortFirstLength_m = 10.0;
constexpr int kLengthCount = 8;

std::vector<double> multiples(double first_m) {
  std::vector<double> lengths;
  for (int k = 1; k <= kLengthCount; ++k) lengths.push_back(first_m * k);
  return lengths;
}

}  // namespace

std::vector<double> kitti_segment_lengths_m() { return multiples(kKittiFirstLength_m); }
std::vector<double> short_segment_lengths_m() { return multiples(kShortFirstLength_m); }

std::vector<double> cumulative_path_length_m(std::span<const SE3> poses) {
  std::vector<double> d(poses.size(), 0.0);
  for (std::size_t k = 1; k < poses.size(); ++k) {
    d[k] = d[k - 1] + (poses[k].translation() - poses[k - 1].translation()).norm();
  }
  return d;
}

KittiRpeResult compute_kitti_rpe(std::span<const SE3> estimate, std::span<const SE3> groundtruth,
                                 const KittiRpeOptions& options) {
  if (estimate.size() != groundtruth.size()) {
    throw InputError("compute_kitti_rpe: " + std::to_string(estimate.size()) + " estimate poses but " +
                     std::to_string(groundtruth.size()) + " ground-truth poses");
  }
  if (options.step_frames == 0) throw InputError("compute_kitti_rpe: step_frames must be >= 1");
  const std::vector<double> dist = cumulative_path_length_m(groundtruth);
  const double path_m = dist.empty() ? 0.0 : dist.back();

  KittiRpeResult r;
  r.segment_lengths_m = !options.segment_lengths_m.empty()         ? options.segment_lengths_m
                        : path_m >= options.short_path_threshold_m ? kitti_segment_lengths_m()
                                                                   : short_segment_lengths_m();
  double t_sum = 0.0, r_sum = 0.0;
  for (const double length_m : r.segment_lengths_m) {
    KittiLengthError per{.length_m = length_m};
    for (std::size_t i = 0; i < dist.size(); i += options.step_frames) {
      const auto it = std::lower_bound(dist.begin() + static_cast<std::ptrdiff_t>(i), dist.end(), dist[i] + length_m);
      if (it == dist.end()) break;  // later first frames reach even less far
      const auto j = static_cast<std::size_t>(it - dist.begin());
      const SE3 error = (groundtruth[i].inverse() * groundtruth[j]).inverse() * (estimate[i].inverse() * estimate[j]);
      const double t_err = error.translation().norm() / length_m;
      const double r_err = error.angle_rad() / length_m;
      per.translation_pct += t_err;
      per.rotation_deg_per_100m += r_err;
      ++per.segment_count;
    }
    t_sum += per.translation_pct;
    r_sum += per.rotation_deg_per_100m;
    r.segment_count += per.segment_count;
    if (per.segment_count > 0) {
      const auto n = static_cast<double>(per.segment_count);
      per.translation_pct *= kPercent / n;
      per.rotation_deg_per_100m *= kDegreesPerRadian * kPerHundredMetres / n;
    }
    r.per_length.push_back(per);
  }
  if (r.segment_count > 0) {
    const auto n = static_cast<double>(r.segment_count);
    r.translation_pct = t_sum * kPercent / n;
    r.rotation_deg_per_100m = r_sum * kDegreesPerRadian * kPerHundredMetres / n;
  }
  return r;
}

}  // namespace farlio::eval
