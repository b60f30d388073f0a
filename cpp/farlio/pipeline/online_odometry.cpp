#include "farlio/pipeline/online_odometry.hpp"

#include <stdexcept>
#include <utility>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/time.hpp"

namespace farlio::pipeline {

OnlineOdometry::OnlineOdometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2,
                               OdometryCallback on_odometry, FrameCallback on_frame, bool keep_registered_points)
    : config_(validated(config)),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      keep_registered_points_(keep_registered_points),
      on_odometry_(std::move(on_odometry)),
      on_frame_(std::move(on_frame)),
      driver_(config, gravity_m_s2, T_imu_lidar, config.fusion.enabled),
      pipeline_(config_) {
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
  FusionDriver::Samples out;
  std::unique_lock emit(emit_mutex_);
  {
    std::lock_guard lock(state_mutex_);
    driver_.add_imu(sample, out);
  }
  if (on_odometry_) {
    for (const auto& s : out) on_odometry_(s);
  }
}

bool OnlineOdometry::add_scan(Scan scan) {
  bool accepted = false;
  std::optional<Scan> replaced;  // the scan that waited, when this newer one takes its place
  {
    std::lock_guard lock(queue_mutex_);
    const double max_wait_ns = busy_wait_limit_ns(config_.registration.max_wait_periods, scan.end_stamp_ns,
                                                  std::exchange(last_added_end_ns_, scan.end_stamp_ns));
    if (!stopping_ && (!busy_ || max_wait_ns > 0.0)) {
      if (pending_) replaced = std::move(pending_);
      pending_ = std::move(scan);
      pending_deadline_ = busy_ ? SteadyClock::now() + std::chrono::nanoseconds(static_cast<std::int64_t>(max_wait_ns))
                                : SteadyClock::time_point::max();
      busy_ = true;
      accepted = true;
    }
  }
  if (accepted) queue_cv_.notify_all();
  if (accepted && !replaced) return true;
  drop_busy(replaced ? *replaced : scan);
  return accepted;
}

void OnlineOdometry::drop_busy(const Scan& scan) {
  {
    std::lock_guard lock(state_mutex_);
    ++dropped_busy_;
  }
  if (on_frame_) on_frame_(busy_frame(scan));
}

void OnlineOdometry::wait_idle() {
  std::unique_lock lock(queue_mutex_);
  queue_cv_.wait(lock, [this] { return !busy_; });
}

void OnlineOdometry::worker_loop() {
  for (;;) {
    Scan scan;
    bool stale = false;
    {
      std::unique_lock lock(queue_mutex_);
      queue_cv_.wait(lock, [this] { return pending_.has_value() || stopping_; });
      if (!pending_) return;  // stopping with nothing left
      scan = std::move(*pending_);
      pending_.reset();
      stale = SteadyClock::now() > pending_deadline_;  // it waited longer than max_wait_periods
    }
    if (stale) {
      drop_busy(scan);
    } else {
      const OdometryFrame frame = process(scan);
      if (on_frame_) on_frame_(frame);
    }
    {
      std::lock_guard lock(queue_mutex_);
      busy_ = pending_.has_value();  // a scan that waited is next
    }
    queue_cv_.notify_all();
  }
}

void OnlineOdometry::set_initial_pose(const SE3& body_pose) {
  std::lock_guard lock(state_mutex_);
  if (started_) throw std::logic_error("OnlineOdometry::set_initial_pose after the first scan");
  requested_initial_pose_ = body_pose;
}

void OnlineOdometry::set_prior_map(std::vector<Eigen::Vector3f> world_points) {
  std::lock_guard lock(pipeline_mutex_);
  pipeline_.set_prior_map(std::move(world_points));  // throws after the first scan
}

OdometryFrame OnlineOdometry::process(const Scan& scan) {
  OdometryFrame out;
  ScanPrior prior;
  std::unique_lock pipeline_lock(pipeline_mutex_);
  {
    std::lock_guard lock(state_mutex_);
    if (!started_) {  // the first scan fixes the start pose (gravity aligned when the IMU came first)
      started_ = true;
      pipeline_.reset_initial_pose(driver_.start_pose(scan.end_stamp_ns, requested_initial_pose_) * T_imu_lidar_);
    }
    prior = driver_.prior(scan, pipeline_.last_twist(), pipeline_.frames() >= 2);
    out.started_ns = fused_clock() ? driver_.clock_ns() : scan.end_stamp_ns;
  }
  register_from_prior(pipeline_, scan, prior, T_lidar_imu_, out);
  if (keep_registered_points_) {
    out.registered_points = pipeline_.backend().frame_points();
    const Eigen::Matrix3f R = out.scan.pose.rotation().cast<float>();
    const Eigen::Vector3f t = out.scan.pose.translation().cast<float>();
    for (auto& p : out.registered_points) p = R * p + t;
  }
  pipeline_lock.unlock();

  std::lock_guard lock(state_mutex_);
  driver_.link(scan, out);
  // without the fusion there is no clock but the scan stamps: the result is ready after its
  // processing time
  out.available_ns = fused_clock() ? driver_.clock_ns() : out.started_ns + seconds_to_ns(out.scan.timings.total_s);
  return out;
}

bool OnlineOdometry::fused_clock() const { return driver_.inertial() && driver_.has_imu(); }

bool OnlineOdometry::inertial() const {
  std::lock_guard lock(state_mutex_);
  return fused_clock();
}

std::optional<fusion::FusionStats> OnlineOdometry::fusion_stats() const {
  std::lock_guard lock(state_mutex_);
  if (!started_) return std::nullopt;
  return driver_.stats();
}

std::vector<std::string> OnlineOdometry::take_warnings() {
  std::lock_guard lock(state_mutex_);
  return driver_.take_warnings();
}

map::MapSnapshot OnlineOdometry::map_snapshot() const {
  std::lock_guard lock(pipeline_mutex_);
  return pipeline_.frames() > 0 ? pipeline_.backend().map_snapshot() : map::MapSnapshot{};
}

Device OnlineOdometry::device() const { return pipeline_.backend().device(); }

const std::string& OnlineOdometry::device_message() const { return pipeline_.device_message(); }

std::size_t OnlineOdometry::scans_dropped_busy() const {
  std::lock_guard lock(state_mutex_);
  return dropped_busy_;
}

}  // namespace farlio::pipeline
