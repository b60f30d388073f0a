#include "farlio/pipeline/pairwise.hpp"

#include <limits>
#include <numeric>

#include "farlio/core/config_fields.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/pipeline/scan_backend.hpp"
#include "farlio/preprocess/preprocess.hpp"

namespace farlio::pipeline {

registration::RegistrationResult register_pair(const std::vector<Eigen::Vector3f>& source,
                                               const std::vector<Eigen::Vector3f>& target, const SE3& initial_guess,
                                               const Config& requested) {
  Config config = validated(requested);
  config.map.voxel_size_m = preprocess::scene_voxel_size_m(target, config.map);
  exec::CpuExecutor executor(config.num_threads);
  map::VoxelMap target_map(config.map, executor);
  target_map.insert(target, Eigen::Vector3f::Zero(), map::PointLimit::constant(config.map.max_points_per_voxel));

  const VoxelMapConfig frame_cfg = frame_map_config(config);
  map::VoxelMap frame(frame_cfg, executor);
  std::vector<std::int32_t> all(source.size());
  std::iota(all.begin(), all.end(), 0);
  const auto kept = preprocess::voxel_downsample(source, all, static_cast<float>(frame_cfg.point_spacing_m), executor);
  std::vector<Eigen::Vector3f> down(kept.size());
  for (std::size_t i = 0; i < kept.size(); ++i) down[i] = source[static_cast<std::size_t>(kept[i])];
  frame.insert(down, Eigen::Vector3f::Zero(), map::PointLimit::constant(frame_cfg.max_points_per_voxel));

  const auto src = registration::source_from_map(frame.view(), frame.voxel_capacity());
  return registration::register_scan(
      src, target_map.view(), initial_guess,
      registration::Thresholds::from_sigma(
          config.threshold.initial_threshold_m,
          registration::point_to_point_precision(config.registration, config.map.covariance_epsilon,
                                                 frame_cfg.point_spacing_m)),
      config.registration, std::numeric_limits<double>::infinity(), executor);
}

}  // namespace farlio::pipeline
