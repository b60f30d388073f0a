#include "farlio/pipeline/fusion_link.hpp"

#include <cmath>

#include "farlio/core/time.hpp"
#include "farlio/deskew/motion_fit.hpp"

namespace farlio::pipeline {
namespace {

// Poses sampled over a scan for the motion regression.
constexpr int kMotionSamples = 11;

std::optional<deskew::ScanMotion> motion_from_fusion(const fusion::SensorFusion& fusion, const Scan& scan,
                                                     const SE3& end_pose, const SE3& T_imu_lidar) {
  if (!scan.has_time() || scan.duration_s() <= 0.0) return std::nullopt;
  std::vector<std::pair<double, SE3>> samples;
  for (int i = 0; i < kMotionSamples; ++i) {
    const double tau = scan.duration_s() * i / (kMotionSamples - 1);
    const auto body = fusion.pose_at(scan.start_stamp_ns + seconds_to_ns(tau));
    if (body) samples.emplace_back(tau, *body * T_imu_lidar);
  }
  if (samples.size() < 2) return std::nullopt;
  return deskew::fit_scan_motion(samples, end_pose);
}

}  // namespace

SE3 gravity_aligned_start(const std::vector<ImuSample>& imu, std::int64_t until_ns) {
  if (imu.empty() || imu.front().stamp_ns > until_ns) return SE3();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : imu) {
    if (s.stamp_ns > until_ns || s.stamp_ns - imu.front().stamp_ns > seconds_to_ns(kGravityAlignmentWindow_s)) break;
    mean += s.accel_m_s2;
    ++n;
  }
  mean /= n;
  if (mean.norm() <= 0.0 || !mean.allFinite()) return SE3();
  const double roll = std::atan2(mean.y(), mean.z());
  const double pitch = std::atan2(-mean.x(), std::hypot(mean.y(), mean.z()));
  const Eigen::Quaterniond q = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return SE3(q, Eigen::Vector3d::Zero());
}

ScanPrior prior_from_fusion(const fusion::SensorFusion& fusion, const Scan& scan, const SE3& T_imu_lidar) {
  ScanPrior prior;
  if (!fusion.initialized()) return prior;
  if (const auto body = fusion.pose_at(scan.end_stamp_ns)) {
    prior.guess = *body * T_imu_lidar;
    prior.motion = motion_from_fusion(fusion, scan, *prior.guess, T_imu_lidar);
  }
  return prior;
}

std::string drop_reason(const FrameResult& result, bool map_started) {
  if (!result.registered && map_started) return "nothing to register against";
  if (result.registration.budget_exceeded) return "registration exceeded its time budget";
  return {};
}

void fuse_scan(fusion::SensorFusion& fusion, std::int64_t stamp_ns, const SE3& body_pose,
               const std::optional<StampedPose>& previous) {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  const bool has_velocity = previous.has_value() && stamp_ns > previous->stamp_ns;
  if (has_velocity) {  // eq. (6) on the body poses
    const double dt = static_cast<double>(stamp_ns - previous->stamp_ns) / kNsPerS;
    velocity = velocity_from_poses(previous->pose, body_pose, dt);
  }
  fusion.add_lidar(stamp_ns, body_pose, velocity, has_velocity);
}

}  // namespace farlio::pipeline
