#include "farlio/pipeline/odometry.hpp"

#include <algorithm>

#include "farlio/core/time.hpp"
#include "farlio/pipeline/fusion_link.hpp"

namespace farlio::pipeline {

Odometry::Odometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2, std::vector<ImuSample> imu,
                   const ReplayOptions& options)
    : config_(config),
      options_(options),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      imu_(std::move(imu)),
      pipeline_(config, T_imu_lidar) {
  if (config.fusion.enabled && !imu_.empty()) {
    fusion_.emplace(config.fusion, gravity_m_s2);
    // the clock starts at the first IMU sample, so the fusion sees every sample before the
    // first scan on its grid (as the online odometry does)
    clock_started_ = true;
    clock_ns_ = imu_.front().stamp_ns;
  }
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
  const std::int64_t step_ns = seconds_to_ns(config_.fusion.step_s);
  if (next_output_ns_ == 0) next_output_ns_ = (clock_ns_ / step_ns + 1) * step_ns;
  // Feed the IMU and step the filter up to each output instant, then emit the estimate.
  auto feed_to = [&](std::int64_t t) {
    while (next_imu_ < imu_.size() && imu_[next_imu_].stamp_ns <= t) fusion_->add_imu(imu_[next_imu_++]);
    fusion_->advance_to(t);
  };
  // The fusion never runs past the recording's last IMU sample: beyond it there is no data, not
  // a gap (results that arrive later are fused at that time, with their delay compensated).
  const std::int64_t fusion_until = std::min(stamp_ns, imu_.back().stamp_ns);
  while (next_output_ns_ <= fusion_until) {
    feed_to(next_output_ns_);
    const auto e = fusion_->estimate();
    if (e.valid && on_odometry) on_odometry({e.stamp_ns, e.pose, e.velocity_body_m_s});
    next_output_ns_ += step_ns;
  }
  feed_to(fusion_until);
  clock_ns_ = stamp_ns;
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
  if (pipeline_.frames() == 0 && fusion_) {  // roll and pitch from the IMU seen so far
    initial_body_pose_ = gravity_aligned_start(imu_, scan.end_stamp_ns);
    pipeline_.reset_initial_pose(initial_body_pose_ * T_imu_lidar_);
  }
  out.started_ns = std::max(scan.end_stamp_ns, clock_ns_);
  advance_clock(out.started_ns);

  const ScanPrior prior = fusion_ ? prior_from_fusion(*fusion_, scan, T_imu_lidar_) : ScanPrior{};
  out.guess_from_fusion = prior.guess.has_value();
  out.scan = pipeline_.process(scan, prior.guess, prior.motion);
  out.processed = true;
  out.body_pose = out.scan.pose * T_lidar_imu_;
  out.available_ns = out.started_ns + seconds_to_ns(latency_s(out.scan));
  busy_until_ns_ = out.available_ns;

  out.drop_reason = drop_reason(out.scan, last_body_.has_value());
  if (out.drop_reason.empty() && fusion_) {
    advance_clock(out.available_ns);
    fuse_scan(*fusion_, scan.end_stamp_ns, out.body_pose, last_body_);
    out.fused = true;
  }
  last_body_ = StampedPose{scan.end_stamp_ns, out.body_pose};
  return out;
}

void Odometry::finish(std::int64_t stamp_ns) { advance_clock(stamp_ns); }

}  // namespace farlio::pipeline
