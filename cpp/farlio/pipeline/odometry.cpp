#include "farlio/pipeline/odometry.hpp"

#include <algorithm>
#include <cmath>

#include "farlio/deskew/motion_fit.hpp"

namespace farlio::pipeline {
namespace {

constexpr double kNsPerS = 1e9;
// IMU samples averaged for the initial roll and pitch (from the start of the recording).
constexpr double kGravityAlignmentWindow_s = 0.2;
// Poses sampled over a scan for the motion regression.
constexpr int kMotionSamples = 11;

std::int64_t to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * kNsPerS)); }

/// Roll and pitch that make the mean specific force of the first samples point up (yaw 0).
SE3 gravity_aligned_start(const std::vector<ImuSample>& imu) {
  if (imu.empty()) return SE3();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : imu) {
    if (s.stamp_ns - imu.front().stamp_ns > to_ns(kGravityAlignmentWindow_s)) break;
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

}  // namespace

Odometry::Odometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2, std::vector<ImuSample> imu,
                   const ReplayOptions& options)
    : config_(config),
      options_(options),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      initial_body_pose_(config.fusion.enabled ? gravity_aligned_start(imu) : SE3()),
      imu_(std::move(imu)),
      pipeline_(config, initial_body_pose_ * T_imu_lidar) {
  if (config.fusion.enabled && !imu_.empty()) fusion_.emplace(config.fusion, gravity_m_s2);
}

std::optional<fusion::FusionStats> Odometry::fusion_stats() const {
  if (!fusion_) return std::nullopt;
  return fusion_->stats();
}

void Odometry::advance_clock(std::int64_t stamp_ns) {
  if (!clock_started_) {  // the clock starts at the first event of the recording
    clock_started_ = true;
    clock_ns_ = stamp_ns;
  }
  if (stamp_ns <= clock_ns_) return;
  if (!fusion_) {
    clock_ns_ = stamp_ns;
    return;
  }
  const std::int64_t step_ns = to_ns(config_.fusion.step_s);
  if (next_output_ns_ == 0) next_output_ns_ = (clock_ns_ / step_ns + 1) * step_ns;
  // Feed the IMU and step the filter up to each output instant, then emit the estimate.
  auto feed_to = [&](std::int64_t t) {
    while (next_imu_ < imu_.size() && imu_[next_imu_].stamp_ns <= t) fusion_->add_imu(imu_[next_imu_++]);
    fusion_->advance_to(t);
  };
  while (next_output_ns_ <= stamp_ns) {
    feed_to(next_output_ns_);
    const auto e = fusion_->estimate();
    if (e.valid && on_odometry) on_odometry({e.stamp_ns, e.pose, e.velocity_body_m_s});
    next_output_ns_ += step_ns;
  }
  feed_to(stamp_ns);
  clock_ns_ = stamp_ns;
}

std::optional<deskew::ScanMotion> Odometry::motion_from_fusion(const Scan& scan, const SE3& end_pose) const {
  if (!scan.has_time() || scan.duration_s() <= 0.0) return std::nullopt;
  std::vector<std::pair<double, SE3>> samples;
  for (int i = 0; i < kMotionSamples; ++i) {
    const double tau = scan.duration_s() * i / (kMotionSamples - 1);
    const auto body = fusion_->pose_at(scan.start_stamp_ns + to_ns(tau));
    if (body) samples.emplace_back(tau, *body * T_imu_lidar_);
  }
  if (samples.size() < 2) return std::nullopt;
  return deskew::fit_scan_motion(samples, end_pose);
}

double Odometry::latency_s(const FrameResult& r) const {
  double base = 0.0;
  switch (options_.latency) {
    case LatencyModel::Measured: base = r.timings.total_s; break;
    case LatencyModel::Zero: base = 0.0; break;
    case LatencyModel::Fixed: base = options_.fixed_latency_s; break;
  }
  return base + options_.added_delay_s;
}

OdometryFrame Odometry::process(const Scan& scan) {
  OdometryFrame out;
  out.scan.stamp_ns = scan.end_stamp_ns;
  if (scan.end_stamp_ns < busy_until_ns_) {
    out.drop_reason = "the pipeline was still busy with the previous scan";
    return out;
  }
  out.started_ns = std::max(scan.end_stamp_ns, clock_ns_);
  advance_clock(out.started_ns);

  std::optional<SE3> guess;
  std::optional<deskew::ScanMotion> motion;
  if (fusion_ && fusion_->initialized()) {
    if (const auto body = fusion_->pose_at(scan.end_stamp_ns)) {
      guess = *body * T_imu_lidar_;
      motion = motion_from_fusion(scan, *guess);
      out.guess_from_fusion = true;
    }
  }
  out.scan = pipeline_.process(scan, guess, motion);
  out.processed = true;
  out.body_pose = out.scan.pose * T_lidar_imu_;
  out.available_ns = out.started_ns + to_ns(latency_s(out.scan));
  busy_until_ns_ = out.available_ns;

  if (!out.scan.registered && last_body_) {
    out.drop_reason = "nothing to register against";
  } else if (out.scan.registration.budget_exceeded) {
    out.drop_reason = "registration exceeded its time budget";
  } else if (fusion_) {
    advance_clock(out.available_ns);
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    const bool has_velocity = last_body_.has_value() && scan.end_stamp_ns > last_body_->stamp_ns;
    if (has_velocity) {  // eq. (6) on the body poses
      const double dt = static_cast<double>(scan.end_stamp_ns - last_body_->stamp_ns) / kNsPerS;
      velocity = velocity_from_poses(last_body_->pose, out.body_pose, dt);
    }
    fusion_->add_lidar(scan.end_stamp_ns, out.body_pose, velocity, has_velocity);
    out.fused = true;
  }
  last_body_ = StampedPose{scan.end_stamp_ns, out.body_pose};
  return out;
}

void Odometry::finish(std::int64_t stamp_ns) { advance_clock(stamp_ns); }

}  // namespace farlio::pipeline
