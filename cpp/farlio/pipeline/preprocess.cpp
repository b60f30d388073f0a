#include "farlio/pipeline/preprocess.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>

#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/range_crop.hpp"

namespace farlio::pipeline {

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
  // (cell key, position in `indices`) sorted: the first of each cell is kept.
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed(indices.size());
  const float inv = 1.0f / cell_m;
  executor.for_each(indices.size(), [&](std::size_t i) {
    keyed[i] = {map::point_key(points[static_cast<std::size_t>(indices[i])], inv), static_cast<std::int32_t>(i)};
  });
  std::vector<std::int32_t> kept = first_of_each_cell(keyed, executor);
  for (auto& k : kept) k = indices[static_cast<std::size_t>(k)];
  return kept;
}

std::vector<std::int32_t> first_of_each_cell(std::vector<std::pair<std::uint64_t, std::int32_t>>& keyed,
                                             exec::CpuExecutor& executor) {
  executor.run([&] { tbb::parallel_sort(keyed.begin(), keyed.end()); });
  std::vector<std::int32_t> kept;
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (keyed[i].first == map::kEmptyKey) break;
    if (i == 0 || keyed[i].first != keyed[i - 1].first) kept.push_back(keyed[i].second);
  }
  return kept;
}

double scene_voxel_size_m(const std::vector<Eigen::Vector3f>& points, const VoxelMapConfig& config) {
  constexpr std::size_t kStride = 16;  // a subsample is enough for a percentile
  constexpr double kPercentile = 0.9;
  if (!config.auto_voxel_size) return config.voxel_size_m;
  std::vector<float> ranges;
  for (std::size_t i = 0; i < points.size(); i += kStride) {
    const float r = points[i].norm();
    if (std::isfinite(r)) ranges.push_back(r);
  }
  if (ranges.empty()) return config.voxel_size_m;
  const auto nth = ranges.begin() + static_cast<std::ptrdiff_t>(kPercentile * static_cast<double>(ranges.size() - 1));
  std::nth_element(ranges.begin(), nth, ranges.end());
  return std::clamp(static_cast<double>(*nth) / config.auto_range_ratio, config.auto_min_voxel_size_m,
                    config.voxel_size_m);
}

}  // namespace farlio::pipeline
