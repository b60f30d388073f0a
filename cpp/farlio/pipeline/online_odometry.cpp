#include "farlio/pipeline/online_odometry.hpp"

#include "farlio/core/time.hpp"
#include "farlio/pipeline/fusion_link.hpp"

namespace farlio::pipeline {

OnlineOdometry::OnlineOdometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2,
                               OdometryCallback on_odometry, FrameCallback on_frame)
    : config_(config),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      on_odometry_(std::move(on_odometry)),
      on_frame_(std::move(on_frame)) {
  if (config.fusion.enabled) fusion_.emplace(config.fusion, gravity_m_s2);
  worker_ = std::thread([this] { worker_loop(); });
}

OnlineOdometry::~OnlineOdometry() { stop(); }

void OnlineOdometry::stop() {
  {
    std::lock_guard lock(queue_mutex_);
    stopping_ = true;
  }
  queue_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void OnlineOdometry::add_imu(const ImuSample& sample) {
  std::vector<OdometrySample> out;
  std::unique_lock emit(emit_mutex_);
  {
    std::lock_guard lock(state_mutex_);
    if (!fusion_) return;
    if (!inertial_decided_ && (startup_imu_.empty() || sample.stamp_ns - startup_imu_.front().stamp_ns <=
                                                           seconds_to_ns(kGravityAlignmentWindow_s))) {
      startup_imu_.push_back(sample);
    }
    // As the replay does: every step sees exactly the samples stamped up to its instant.
    const std::int64_t step_ns = seconds_to_ns(config_.fusion.step_s);
    if (next_output_ns_ == 0) next_output_ns_ = (sample.stamp_ns / step_ns + 1) * step_ns;
    auto emit_step = [&] {
      fusion_->advance_to(next_output_ns_);
      const auto e = fusion_->estimate();
      if (e.valid && inertial_) out.push_back({e.stamp_ns, e.pose, e.velocity_body_m_s});
      next_output_ns_ += step_ns;
    };
    while (next_output_ns_ < sample.stamp_ns) emit_step();
    fusion_->add_imu(sample);
    if (next_output_ns_ == sample.stamp_ns) emit_step();
    fusion_->advance_to(sample.stamp_ns);
  }
  if (on_odometry_)
    for (const auto& s : out) on_odometry_(s);
}

bool OnlineOdometry::add_scan(Scan scan) {
  {
    std::lock_guard lock(queue_mutex_);
    if (!busy_ && !pending_ && !stopping_) {
      pending_ = std::move(scan);
      busy_ = true;
      queue_cv_.notify_all();
      return true;
    }
  }
  {
    std::lock_guard lock(state_mutex_);
    ++dropped_busy_;
  }
  if (on_frame_) {
    OdometryFrame dropped;
    dropped.scan.stamp_ns = scan.end_stamp_ns;
    dropped.drop_reason = "the pipeline was still busy with the previous scan";
    on_frame_(dropped);
  }
  return false;
}

void OnlineOdometry::wait_idle() {
  std::unique_lock lock(queue_mutex_);
  queue_cv_.wait(lock, [this] { return !busy_; });
}

void OnlineOdometry::worker_loop() {
  for (;;) {
    Scan scan;
    {
      std::unique_lock lock(queue_mutex_);
      queue_cv_.wait(lock, [this] { return pending_.has_value() || stopping_; });
      if (!pending_) return;  // stopping with nothing left
      scan = std::move(*pending_);
      pending_.reset();
    }
    const OdometryFrame frame = process(scan);
    if (on_frame_) on_frame_(frame);
    {
      std::lock_guard lock(queue_mutex_);
      busy_ = false;
    }
    queue_cv_.notify_all();
  }
}

OdometryFrame OnlineOdometry::process(const Scan& scan) {
  OdometryFrame out;
  ScanPrior prior;
  {
    std::lock_guard lock(state_mutex_);
    if (!inertial_decided_) {  // the first scan fixes the mode and the start pose
      inertial_decided_ = true;
      inertial_ = fusion_.has_value() && !startup_imu_.empty();
      const SE3 start = inertial_ ? gravity_aligned_start(startup_imu_, scan.end_stamp_ns) : SE3();
      startup_imu_.clear();
      pipeline_.emplace(config_, start * T_imu_lidar_);
    }
    if (inertial_) prior = prior_from_fusion(*fusion_, scan, T_imu_lidar_);
    out.started_ns = inertial_ ? fusion_->estimate().stamp_ns : scan.end_stamp_ns;
  }
  out.guess_from_fusion = prior.guess.has_value();
  out.scan = pipeline_->process(scan, prior.guess, prior.motion);
  out.processed = true;
  out.body_pose = out.scan.pose * T_lidar_imu_;

  std::lock_guard lock(state_mutex_);
  out.drop_reason = drop_reason(out.scan, last_body_.has_value());
  if (out.drop_reason.empty() && inertial_) {
    fuse_scan(*fusion_, scan.end_stamp_ns, out.body_pose, last_body_);
    out.fused = true;
    out.available_ns = fusion_->estimate().stamp_ns;
  }
  last_body_ = StampedPose{scan.end_stamp_ns, out.body_pose};
  return out;
}

bool OnlineOdometry::inertial() const {
  std::lock_guard lock(state_mutex_);
  return inertial_;
}

std::optional<fusion::FusionStats> OnlineOdometry::fusion_stats() const {
  std::lock_guard lock(state_mutex_);
  if (!inertial_) return std::nullopt;
  return fusion_->stats();
}

std::size_t OnlineOdometry::scans_dropped_busy() const {
  std::lock_guard lock(state_mutex_);
  return dropped_busy_;
}

}  // namespace farlio::pipeline
