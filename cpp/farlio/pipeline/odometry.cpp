#include "farlio/pipeline/odometry.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "farlio/core/clock_check.hpp"
#include "farlio/core/error.hpp"
#include "farlio/core/time.hpp"
#include "farlio/fusion/gyro_unit_detector.hpp"

namespace farlio::pipeline {
namespace {

void check_latency(double value_s, const char* name) {
  if (value_s >= 0.0 && value_s <= kMaxDuration_s) return;  // false for NaN
  throw std::invalid_argument(std::string("ReplayOptions.") + name + " must be in [0, " +
                              std::to_string(static_cast<int>(kMaxDuration_s)) + "] s, got " + std::to_string(value_s));
}

bool earlier(const ImuSample& a, const ImuSample& b) { return a.stamp_ns < b.stamp_ns; }

/// Sorts the samples by stamp; a warning when they were not.
void sort_by_stamp(std::vector<ImuSample>& imu, std::vector<std::string>& warnings) {
  std::size_t out_of_order = 0;
  for (std::size_t i = 1; i < imu.size(); ++i) out_of_order += earlier(imu[i], imu[i - 1]) ? 1 : 0;
  if (out_of_order == 0) return;
  std::stable_sort(imu.begin(), imu.end(), earlier);
  warnings.push_back("IMU samples are not in time order (" + std::to_string(out_of_order) + " of " +
                     std::to_string(imu.size()) + " are older than the sample before them): sorted by stamp");
}

/// The accelerometers of the first samples the unit detection looks at.
std::vector<Eigen::Vector3d> first_accels(const std::vector<ImuSample>& imu, int count) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < imu.size() && out.size() < static_cast<std::size_t>(count); ++i) {
    out.push_back(imu[i].accel_m_s2);
  }
  return out;
}

}  // namespace

void validate_replay_options(const ReplayOptions& options) {
  check_latency(options.fixed_latency_s, "fixed_latency_s");
  check_latency(options.added_delay_s, "added_delay_s");
}

Odometry::Odometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2, std::vector<ImuSample> imu,
                   const ReplayOptions& options)
    : options_(options),
      max_wait_periods_(config.registration.max_wait_periods),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      imu_(std::move(imu)),
      driver_(config, gravity_m_s2, T_imu_lidar, config.fusion.enabled && !imu_.empty()),
      pipeline_(config, T_imu_lidar) {
  validate_replay_options(options_);
  if (!driver_.inertial()) return;
  sort_by_stamp(imu_, warnings_);
  if (std::string silent = fusion::silent_accelerometer(first_accels(imu_, config.fusion.units.accel_samples));
      !silent.empty()) {
    warnings_.push_back(std::move(silent));
    driver_.stop_fusion();
  }
}

void Odometry::set_initial_pose(const SE3& body_pose) {
  if (pipeline_.frames() > 0) throw std::logic_error("Odometry::set_initial_pose after the first scan");
  requested_initial_pose_ = body_pose;
}

std::vector<std::string> Odometry::take_warnings() {
  std::vector<std::string> out = std::exchange(warnings_, {});
  for (std::string& w : driver_.take_warnings()) out.push_back(std::move(w));
  return out;
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
    // a gap (results stamped before it that arrive later are fused at that time, with their delay
    // compensated; results stamped after it wait for samples that never come and are not fused).
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

bool Odometry::dropped_as_busy(const Scan& scan, std::int64_t previous_end_ns) const {
  if (scan.end_stamp_ns >= busy_until_ns_) return false;  // the pipeline is free when it arrives
  // it waits for the pipeline up to max_wait_periods (<= 1: the next scan, one period later, has
  // not arrived by then)
  return static_cast<double>(busy_until_ns_ - scan.end_stamp_ns) >
         busy_wait_limit_ns(max_wait_periods_, scan.end_stamp_ns, previous_end_ns);
}

OdometryFrame Odometry::process(const Scan& scan) {
  const std::int64_t previous_end_ns = std::exchange(last_scan_end_ns_, scan.end_stamp_ns);
  if (dropped_as_busy(scan, previous_end_ns)) return busy_frame(scan);
  if (!clock_started_ && driver_.inertial()) {
    // the clock starts at the first IMU sample, so the fusion sees every sample before the
    // first scan on its grid (as the online odometry does), or at a first scan before the IMU
    const double tolerance_s = driver_.max_bridged_gap_s();
    const ClockCheck check = check_clocks({imu_.front().stamp_ns, imu_.back().stamp_ns},
                                          {scan.end_stamp_ns, scan.end_stamp_ns}, tolerance_s);
    if (!check.error.empty() && scan.end_stamp_ns > imu_.back().stamp_ns) throw InputError("Odometry: " + check.error);
    clock_started_ = true;
    clock_ns_ = std::min(imu_.front().stamp_ns, scan.end_stamp_ns);
  }
  OdometryFrame out;
  out.started_ns = std::max(scan.end_stamp_ns, clock_ns_);  // later when it waited for the pipeline
  advance_clock(out.started_ns);
  if (pipeline_.frames() == 0 && (driver_.inertial() || requested_initial_pose_)) {
    // roll and pitch from the IMU seen so far; position and yaw as requested
    initial_body_pose_ = driver_.start_pose(scan.end_stamp_ns, requested_initial_pose_);
    pipeline_.reset_initial_pose(initial_body_pose_ * T_imu_lidar_);
  }

  const ScanPrior prior = driver_.prior(scan, pipeline_.last_twist(), pipeline_.frames() >= 2);
  register_from_prior(pipeline_, scan, prior, T_lidar_imu_, out);
  out.available_ns = out.started_ns + seconds_to_ns(latency_s(out.scan));
  busy_until_ns_ = out.available_ns;

  advance_clock(out.available_ns);  // the result reaches the fusion when it is available
  driver_.link(scan, out);
  return out;
}

void Odometry::finish(std::int64_t stamp_ns) { advance_clock(stamp_ns); }

}  // namespace farlio::pipeline
