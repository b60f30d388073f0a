#include "farlio/pipeline/scan_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "farlio/pipeline/preprocess.hpp"

namespace farlio::pipeline {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Used as the LiDAR period when neither stamps nor per-point times give one (10 Hz).
constexpr double kFallbackPeriod_s = 0.1;
constexpr double kNsPerS = 1e9;

VoxelMapConfig frame_map_config(const Config& c) {
  VoxelMapConfig f = c.map;
  // the frame map keeps the submap's spacing (the scan is downsampled to it) with a lower cap
  f.point_spacing_m = map::point_spacing_m(c.map);
  f.max_points_per_voxel = c.density.frame_map_max_points_per_voxel;
  f.refresh_covariances = false;
  f.removal_radius_m = std::numeric_limits<double>::infinity();
  return f;
}

}  // namespace

ScanPipeline::ScanPipeline(const Config& config, const SE3& initial_pose)
    : config_(config),
      executor_(config.num_threads),
      map_(config.map, executor_),
      frame_map_(frame_map_config(config), executor_),
      threshold_(config.threshold),
      initial_pose_(initial_pose),
      last_pose_(initial_pose),
      prev_pose_(initial_pose) {}

void ScanPipeline::reset_initial_pose(const SE3& initial_pose) {
  if (frames_ > 0) throw std::logic_error("ScanPipeline::reset_initial_pose after the first scan");
  initial_pose_ = last_pose_ = prev_pose_ = initial_pose;
}

registration::Vec6d ScanPipeline::last_twist() const {
  if (frames_ < 2 || last_stamp_ns_ <= prev_stamp_ns_) return registration::Vec6d::Zero();
  const double dt = static_cast<double>(last_stamp_ns_ - prev_stamp_ns_) / kNsPerS;
  return (prev_pose_.inverse() * last_pose_).log() / dt;
}

SE3 ScanPipeline::predict(std::int64_t stamp_ns) const {
  if (frames_ == 0) return initial_pose_;
  const double dt = static_cast<double>(stamp_ns - last_stamp_ns_) / kNsPerS;
  return last_pose_ * SE3::exp(last_twist() * dt);
}

FrameResult ScanPipeline::process(const Scan& scan, const std::optional<SE3>& initial_guess,
                                  const std::optional<deskew::ScanMotion>& motion) {
  const auto t_start = Clock::now();
  FrameResult out;
  out.stamp_ns = scan.end_stamp_ns;
  out.input_points = scan.size();

  // 0. the first scan with points fixes the map's scale
  if (!scale_fixed_ && !scan.empty()) {
    scale_fixed_ = true;
    const double voxel = scene_voxel_size_m(scan.points, config_.map);
    if (voxel != config_.map.voxel_size_m) {
      config_.map.voxel_size_m = voxel;
      map_ = map::VoxelMap(config_.map, executor_);
      frame_map_ = map::VoxelMap(frame_map_config(config_), executor_);
    }
    config_.map.auto_voxel_size = false;  // the effective config states the size used
  }

  // 1. preprocess: crop, undistort into the scan-end frame, downsample to the map spacing
  auto t0 = Clock::now();
  const std::vector<std::int32_t> cropped = crop_by_range(scan.points, config_.preprocess);
  std::vector<Eigen::Vector3f> points(scan.points.size());
  const deskew::ScanMotion scan_motion =
      motion ? *motion
             : deskew::ScanMotion::constant_twist(last_twist().cast<float>(), static_cast<float>(scan.duration_s()));
  const bool undistort = config_.preprocess.undistort && scan.has_time() && !scan_motion.is_identity();
  executor_.for_each(cropped.size(), [&](std::size_t k) {
    const auto i = static_cast<std::size_t>(cropped[k]);
    points[i] = undistort ? deskew::deskew_point(scan_motion, scan.points[i], scan.time_s[i]) : scan.points[i];
  });
  const std::vector<std::int32_t> kept = voxel_downsample(points, cropped, map_.spacing_m(), executor_);
  std::vector<Eigen::Vector3f> frame(kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) frame[k] = points[static_cast<std::size_t>(kept[k])];
  out.kept_points = frame.size();
  out.timings.preprocess_s = seconds_since(t0);

  // 2. source covariances from the per-scan frame map (sensor frame), and the scan's density
  t0 = Clock::now();
  frame_map_.clear();
  frame_map_.insert(frame, Eigen::Vector3f::Zero(), map::PointLimit::constant(config_.density.frame_map_max_points_per_voxel));
  const registration::SourceCloud source = registration::source_from_map(frame_map_.view(), frame_map_.voxel_capacity());
  out.source_points = source.size();
  const int n_max = config_.map.max_points_per_voxel, k = config_.map.covariance_neighbors;
  map::PointLimit limit = map::PointLimit::constant(n_max);
  if (config_.density.enabled) {
    const double density = frame_map_.mean_points_per_voxel(Eigen::Vector3f::Zero(), config_.density.close_range_m);
    if (density > 0) {
      const int close = std::clamp(static_cast<int>(density), k, n_max);
      limit = {close, static_cast<float>(config_.density.close_range_m),
               static_cast<float>(config_.density.slope_points_per_m), std::min(k, close)};
    }
  }
  out.density_limit = limit.close_limit;
  out.timings.covariance_s = seconds_since(t0);

  // 3. registration against the submap
  t0 = Clock::now();
  const double period_s = frames_ > 0 && scan.end_stamp_ns > last_stamp_ns_
                              ? static_cast<double>(scan.end_stamp_ns - last_stamp_ns_) / kNsPerS
                              : (scan.duration_s() > 0 ? scan.duration_s() : kFallbackPeriod_s);
  out.initial_guess = initial_guess ? *initial_guess : predict(scan.end_stamp_ns);
  out.sigma_m = threshold_.sigma_m();
  SE3 pose = out.initial_guess;
  if (map_.num_voxels() > 0 && !source.points.empty()) {
    out.registration = registration::register_scan(source, map_.view(), out.initial_guess,
                                                   registration::Thresholds::from_sigma(out.sigma_m, registration::point_to_point_precision(
                                                       config_.registration, config_.map.covariance_epsilon, map_.spacing_m())),
                                                   config_.registration, config_.registration.time_budget_factor * period_s,
                                                   executor_);
    out.registered = true;
    pose = out.registration.pose;
    threshold_.update(out.initial_guess.inverse() * pose);
  }
  out.pose = pose;
  out.timings.registration_s = seconds_since(t0);

  // 4. submap update with the adaptive density, then removal of far voxels
  t0 = Clock::now();
  std::vector<Eigen::Vector3f> world(frame.size());
  const Eigen::Matrix3f R = pose.rotation().cast<float>();
  const Eigen::Vector3f t = pose.translation().cast<float>();
  executor_.for_each(frame.size(), [&](std::size_t i) { world[i] = R * frame[i] + t; });
  out.map_insert = map_.insert(world, t, limit);
  out.removed_voxels = map_.remove_far(t);
  out.map_voxels = map_.num_voxels();
  out.map_points = map_.num_points();
  out.timings.map_update_s = seconds_since(t0);

  // 5. velocity from consecutive poses (eq. 6) and the constant-velocity state
  if (frames_ > 0 && scan.end_stamp_ns > last_stamp_ns_) {
    const double dt = static_cast<double>(scan.end_stamp_ns - last_stamp_ns_) / kNsPerS;
    out.velocity_body_m_s = velocity_from_poses(last_pose_, pose, dt);
    out.angular_velocity_body_rad_s = (last_pose_.inverse() * pose).log().tail<3>() / dt;
  }
  prev_pose_ = last_pose_;
  prev_stamp_ns_ = last_stamp_ns_;
  last_pose_ = pose;
  last_stamp_ns_ = scan.end_stamp_ns;
  ++frames_;
  out.timings.total_s = seconds_since(t_start);
  return out;
}

}  // namespace farlio::pipeline
