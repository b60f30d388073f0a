#include "farlio/pipeline/fusion_driver.hpp"

#include <algorithm>
#include <cmath>

#include "farlio/core/time.hpp"
#include "farlio/deskew/motion_fit.hpp"
#include "farlio/fusion/lidar_measurement.hpp"

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

bool in_gravity_window(const ImuSample& first, const ImuSample& s) {
  return s.stamp_ns - first.stamp_ns <= seconds_to_ns(kGravityAlignmentWindow_s);
}

}  // namespace

SE3 gravity_aligned_start(const std::vector<ImuSample>& imu, std::int64_t until_ns) {
  if (imu.empty() || imu.front().stamp_ns > until_ns) return SE3();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : imu) {
    if (s.stamp_ns > until_ns || !in_gravity_window(imu.front(), s)) break;
    mean += s.accel_m_s2;
    ++n;
  }
  mean /= n;
  if (mean.norm() <= 0.0 || !mean.allFinite()) return SE3();
  const double roll = std::atan2(mean.y(), mean.z());
  const double pitch = std::atan2(-mean.x(), std::hypot(mean.y(), mean.z()));
  const Eigen::Quaterniond q =
      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return SE3(q, Eigen::Vector3d::Zero());
}

std::string drop_reason(const FrameResult& result, bool map_started) {
  if (!result.failure.empty()) {
    return result.map_restarted ? result.failure + "; the map restarted from this scan" : result.failure;
  }
  if (!result.registered && map_started) return "nothing to register against";
  if (result.registration.budget_exceeded) return "registration exceeded its time budget";
  return {};
}

FusionDriver::FusionDriver(const Config& config, double gravity_m_s2, const SE3& T_imu_lidar, bool inertial)
    : registration_config_(config.registration), T_imu_lidar_(T_imu_lidar) {
  if (inertial) fusion_.emplace(config.fusion, gravity_m_s2);
}

void FusionDriver::emit_step(Samples& out) {
  fusion_->advance_to(next_output_ns_);
  const fusion::BodyEstimate e = fusion_->estimate();
  if (e.valid) out.push_back({e.stamp_ns, e.pose, e.velocity_body_m_s});
  next_output_ns_ += fusion_->step_ns();
}

void FusionDriver::add_imu(const ImuSample& sample, Samples& out) {
  if (!fusion_) return;
  if (startup_imu_.empty() || in_gravity_window(startup_imu_.front(), sample)) startup_imu_.push_back(sample);
  // the output grid: whole multiples of the step, the first after the first sample
  const std::int64_t step_ns = fusion_->step_ns();
  if (next_output_ns_ == 0) next_output_ns_ = (sample.stamp_ns / step_ns + 1) * step_ns;
  while (next_output_ns_ < sample.stamp_ns) emit_step(out);  // instants before the sample: without it
  fusion_->add_imu(sample);
  advance_to(sample.stamp_ns, out);
}

void FusionDriver::advance_to(std::int64_t stamp_ns, Samples& out) {
  if (!fusion_) return;
  while (next_output_ns_ != 0 && next_output_ns_ <= stamp_ns) emit_step(out);
  fusion_->advance_to(stamp_ns);
  clock_ns_ = std::max(clock_ns_, stamp_ns);
}

SE3 FusionDriver::start_pose(std::int64_t first_scan_end_ns) const {
  return fusion_ ? gravity_aligned_start(startup_imu_, first_scan_end_ns) : SE3();
}

ScanPrior FusionDriver::prior(const Scan& scan) const {
  ScanPrior prior;
  if (!fusion_ || !fusion_->initialized()) return prior;
  if (const auto body = fusion_->pose_at(scan.end_stamp_ns)) {
    prior.guess = *body * T_imu_lidar_;
    prior.motion = motion_from_fusion(*fusion_, scan, *prior.guess, T_imu_lidar_);
  }
  return prior;
}

void FusionDriver::link(const Scan& scan, OdometryFrame& frame) {
  frame.drop_reason = drop_reason(frame.scan, last_body_.has_value());
  std::optional<Mat6d> covariance;
  if (frame.scan.registered && frame.scan.registration.system.inliers > 0) {
    covariance = registration::covariance_from_information(registration::body_information(
        frame.scan.registration.system.H, T_imu_lidar_, registration_config_.covariance_scale));
    frame.degeneracy = registration::analyze_degeneracy(*covariance, registration_config_);
    // the registration held these at the fusion's prior: the scan says nothing there
    if (registration_config_.hold_degenerate_directions && frame.guess_from_fusion) {
      covariance = registration::release_degenerate_directions(*covariance, *frame.degeneracy);
    }
  }
  if (frame.drop_reason.empty() && fusion_) {
    const std::int64_t stamp_ns = scan.end_stamp_ns;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    std::optional<Eigen::Matrix3d> velocity_covariance;
    const bool has_velocity = last_body_.has_value() && stamp_ns > last_body_->stamp_ns;
    if (has_velocity) {  // eq. (6) on the body poses
      const double dt_s = ns_to_seconds(stamp_ns - last_body_->stamp_ns);
      velocity = velocity_from_poses(last_body_->pose, frame.body_pose, dt_s);
      if (covariance && last_covariance_) {
        velocity_covariance =
            fusion::velocity_measurement_covariance(*covariance, *last_covariance_, dt_s, fusion_->config());
      }
    }
    fusion_->add_lidar(stamp_ns, frame.body_pose, velocity, has_velocity, covariance, velocity_covariance);
    frame.fused = true;
  }
  last_body_ = StampedPose{scan.end_stamp_ns, frame.body_pose};
  last_covariance_ = covariance;
}

std::optional<fusion::FusionStats> FusionDriver::stats() const {
  if (!fusion_) return std::nullopt;
  return fusion_->stats();
}

}  // namespace farlio::pipeline
