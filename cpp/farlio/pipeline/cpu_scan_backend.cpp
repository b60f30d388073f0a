#include "farlio/pipeline/cpu_scan_backend.hpp"

#include <atomic>

#include "farlio/preprocess/downsampling_keys.hpp"
#include "farlio/preprocess/preprocess_point.hpp"

namespace farlio::pipeline {

CpuScanBackend::CpuScanBackend(const Config& config)
    : config_(config),
      executor_(config.num_threads),
      map_(config.map, executor_),
      frame_map_(frame_map_config(config), executor_) {
  // the threads up before the first scan, whose latency would otherwise include their start
  // (KITTI's first frame: preprocessing 1.0 ms on 2 threads instead of 2.3 ms, docs/performance.md)
  executor_.warm_up();
}

void CpuScanBackend::reset(const Config& config) {
  config_ = config;
  map_ = map::VoxelMap(config_.map, executor_);
  frame_map_ = map::VoxelMap(frame_map_config(config_), executor_);
}

std::size_t CpuScanBackend::preprocess(const Scan& scan, const deskew::ScanMotion& motion, bool undistort) {
  const preprocess::PreprocessParams pp{preprocess::RangeCrop::from(config_.preprocess),
                                        deskew::DeskewTable::sample(motion, static_cast<float>(scan.duration_s())),
                                        undistort, 1.0f / map_.spacing_m()};
  // one pass: each thread drops the non-finite points of its block of the scan, crops the rest
  // and deduplicates its cells
  const float* times = scan.has_time() ? scan.time_s.data() : nullptr;
  std::atomic<std::size_t> non_finite{0};
  const std::vector<std::int32_t>& kept = downsampler_.first_of_each_cell(
      scan.size(), executor_, [&](std::size_t first, std::size_t count, std::uint64_t* keys) {
        preprocess::downsampling_keys(scan.points.data() + first, count, pp, keys);
        const std::size_t dropped =
            preprocess::drop_non_finite(scan.points.data() + first, times ? times + first : nullptr, count, keys);
        if (dropped > 0) non_finite.fetch_add(dropped, std::memory_order_relaxed);
      });
  non_finite_points_ = non_finite.load();
  // then only the kept points are undistorted
  frame_.resize(kept.size());
  executor_.for_each(kept.size(), [&](std::size_t k) {
    const auto i = static_cast<std::size_t>(kept[k]);
    frame_[k] = preprocess::undistorted_point(scan.points[i], undistort ? scan.time_s[i] : 0.0f, pp);
  });
  return frame_.size();
}

SourceSummary CpuScanBackend::build_source(double density_range_m, bool covariances) {
  frame_map_.clear();
  frame_map_.insert(frame_, Eigen::Vector3f::Zero(),
                    map::PointLimit::constant(config_.density.frame_map_max_points_per_voxel),
                    covariances ? map::CovarianceUpdate::Compute : map::CovarianceUpdate::Skip);
  registration::source_from_map(frame_map_.view(), frame_map_.voxel_capacity(), source_);
  return {source_.size(), frame_map_.mean_points_per_voxel(Eigen::Vector3f::Zero(), density_range_m)};
}

registration::RegistrationResult CpuScanBackend::register_source(const SE3& initial_guess,
                                                                 const registration::Thresholds& th,
                                                                 const RegistrationConfig& config,
                                                                 double time_budget_s) {
  return registration::register_scan(source_, map_.view(), initial_guess, th, config, time_budget_s, executor_);
}

map::InsertStats CpuScanBackend::update_map(const SE3& pose, const map::PointLimit& limit,
                                            std::size_t* removed_voxels) {
  std::vector<Eigen::Vector3f> world(frame_.size());
  const Eigen::Matrix3f R = pose.rotation().cast<float>();
  const Eigen::Vector3f t = pose.translation().cast<float>();
  executor_.for_each(frame_.size(), [&](std::size_t i) { world[i] = R * frame_[i] + t; });
  const map::InsertStats stats = map_.insert(world, t, limit);
  *removed_voxels = map_.remove_far(t);
  return stats;
}

void CpuScanBackend::load_map(const std::vector<Eigen::Vector3f>& world_points) {
  map_.insert(world_points, Eigen::Vector3f::Zero(), map::PointLimit::constant(config_.map.max_points_per_voxel));
}

}  // namespace farlio::pipeline
