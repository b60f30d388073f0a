#include "farlio/preprocess/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "farlio/map/voxel_update.hpp"
#include "farlio/preprocess/cell_downsampler.hpp"
#include "farlio/preprocess/range_crop.hpp"

namespace farlio::preprocess {

std::vector<std::int32_t> crop_by_range(const std::vector<Eigen::Vector3f>& points, const PreprocessConfig& config) {
  const RangeCrop crop = RangeCrop::from(config);
  std::vector<std::int32_t> kept;
  kept.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (crop.keeps(points[i])) kept.push_back(static_cast<std::int32_t>(i));
  }
  return kept;
}

std::vector<std::int32_t> voxel_downsample(const std::vector<Eigen::Vector3f>& points,
                                           const std::vector<std::int32_t>& indices, float cell_m,
                                           exec::CpuExecutor& executor) {
  // the cell key of each point in the order of `indices`: the first of each cell is kept
  std::vector<std::uint64_t> keys(indices.size());
  const float inv = 1.0f / cell_m;
  executor.for_each(indices.size(), [&](std::size_t i) {
    keys[i] = map::point_key(points[static_cast<std::size_t>(indices[i])], inv);
  });
  CellDownsampler downsampler;
  std::vector<std::int32_t> kept = downsampler.first_of_each_cell(keys.data(), keys.size(), executor);
  for (auto& k : kept) k = indices[static_cast<std::size_t>(k)];
  return kept;
}

std::size_t occupied_voxels(const std::vector<Eigen::Vector3f>& points, double voxel_m, std::size_t max_points,
                            std::size_t enough) {
  const std::size_t stride = std::max<std::size_t>(1, (points.size() + max_points - 1) / max_points);
  const auto inv = static_cast<float>(1.0 / voxel_m);
  std::unordered_set<std::uint64_t> keys;
  for (std::size_t i = 0; i < points.size() && keys.size() < enough; i += stride) {
    if (points[i].allFinite()) keys.insert(map::point_key(points[i], inv));
  }
  return keys.size();
}

double scene_voxel_size_m(const std::vector<Eigen::Vector3f>& points, const VoxelMapConfig& config) {
  constexpr std::size_t kStride = 16;  // a subsample is enough for a percentile
  constexpr double kPercentile = 0.9;
  constexpr std::size_t kCountedPoints = 1 << 16;  // enough to count voxels of 0.5 m and more
  constexpr double kShrink = 0.9;                  // the voxel's step down while too few are filled
  if (!config.auto_voxel_size) return config.voxel_size_m;
  std::vector<float> ranges;
  for (std::size_t i = 0; i < points.size(); i += kStride) {
    const float r = points[i].norm();
    if (std::isfinite(r)) ranges.push_back(r);
  }
  if (ranges.empty()) return config.voxel_size_m;
  const auto nth = ranges.begin() + static_cast<std::ptrdiff_t>(kPercentile * static_cast<double>(ranges.size() - 1));
  std::nth_element(ranges.begin(), nth, ranges.end());
  const auto enough = static_cast<std::size_t>(config.auto_min_voxels);
  double voxel = std::clamp(static_cast<double>(*nth) / config.auto_range_ratio, config.auto_min_voxel_size_m,
                            config.voxel_size_m);
  while (voxel > config.auto_min_voxel_size_m && occupied_voxels(points, voxel, kCountedPoints, enough) < enough) {
    voxel = std::max(config.auto_min_voxel_size_m, voxel * kShrink);
  }
  return voxel;
}

}  // namespace farlio::preprocess
