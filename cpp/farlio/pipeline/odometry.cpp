#include "farlio/pipeline/odometry.hpp"

#include <algorithm>

#include "farlio/core/time.hpp"

namespace farlio::pipeline {

Odometry::Odometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2, std::vector<ImuSample> imu,
                   const ReplayOptions& options)
    : options_(options),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      imu_(std::move(imu)),
      driver_(config, gravity_m_s2, T_imu_lidar, config.fusion.enabled && !imu_.empty()),
      pipeline_(config, T_imu_lidar) {
  if (driver_.inertial()) {
    // the clock starts at the first IMU sample, so the fusion sees every sample before the
    // first scan on its grid (as the online odometry does)
    clock_started_ = true;
    clock_ns_ = imu_.front().stamp_ns;
  }
}

std::optional<fusion::FusionStats> Odometry::fusion_stats() const { return driver_.stats(); }

void Odometry::advance_clock(std::int64_t stamp_ns) {
  if (!clock_started_) {  // the clock starts at the first event of the recording
    clock_started_ = true;
    clock_ns_ = stamp_ns;
  }
  if (stamp_ns <= clock_ns_) return;
  if (driver_.inertial()) {
    // The fusion never runs past the recording's last IMU sample: beyond it there is no data, not
    // a gap (results that arrive later are fused at that time, with their delay compensated).
    const std::int64_t fusion_until = std::min(stamp_ns, imu_.back().stamp_ns);
    outputs_.clear();
    while (next_imu_ < imu_.size() && imu_[next_imu_].stamp_ns <= fusion_until) {
      driver_.add_imu(imu_[next_imu_++], outputs_);
    }
    driver_.advance_to(fusion_until, outputs_);
    if (on_odometry) {
      for (const OdometrySample& s : outputs_) on_odometry(s);
    }
  }
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
  if (scan.end_stamp_ns < busy_until_ns_) return busy_frame(scan);
  OdometryFrame out;
  out.started_ns = std::max(scan.end_stamp_ns, clock_ns_);
  advance_clock(out.started_ns);
  if (pipeline_.frames() == 0 && driver_.inertial()) {  // roll and pitch from the IMU seen so far
    initial_body_pose_ = driver_.start_pose(scan.end_stamp_ns);
    pipeline_.reset_initial_pose(initial_body_pose_ * T_imu_lidar_);
  }

  const ScanPrior prior = driver_.prior(scan);
  out.guess_from_fusion = prior.guess.has_value();
  out.scan = pipeline_.process(scan, prior.guess, prior.motion);
  out.processed = true;
  out.body_pose = out.scan.pose * T_lidar_imu_;
  out.available_ns = out.started_ns + seconds_to_ns(latency_s(out.scan));
  busy_until_ns_ = out.available_ns;

  advance_clock(out.available_ns);  // the result reaches the fusion when it is available
  driver_.link(scan, out);
  return out;
}

void Odometry::finish(std::int64_t stamp_ns) { advance_clock(stamp_ns); }

}  // namespace farlio::pipeline
