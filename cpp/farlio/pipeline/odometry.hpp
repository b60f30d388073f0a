#pragma once
// LiDAR-inertial odometry (paper Fig. 2): the scan pipeline and the sensor fusion in a feedback
// loop, replayed on a simulated clock so that a run is deterministic for a given latency model.
//
// For every scan, at the moment the pipeline starts on it:
//   the fusion (advanced with the IMU up to that moment) gives the initial guess at the scan end
//   and the motion during the scan (regression over its pose history, for the undistortion);
//   the scan pipeline registers the scan;
//   its result becomes available after the latency (measured processing time, zero, a fixed
//   value, plus an optional added delay) and is fused as a delayed measurement;
//   the fusion's output at every 10 ms step is the odometry.
// A scan that arrives while the pipeline is still busy waits for it up to
// registration.max_wait_periods, as in the online odometry, and is dropped when it would wait
// longer (at once with 0, as in the paper). A scan whose registration ran out of its time budget
// is dropped. Without IMU samples, or with fusion.enabled off,
// the scan pipeline runs alone on its constant-velocity model (LiDAR-only odometry).
// The clock starts at the first IMU sample, or at the first scan when that ends earlier: scans
// before the IMU starts run LiDAR-only (as in the online odometry), the fusion takes over from
// the first scan after it. IMU samples out of time order are sorted (with a warning); a first
// scan after the IMU's last sample is an InputError (the clocks do not overlap).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/types.hpp"
#include "farlio/fusion/sensor_fusion.hpp"
#include "farlio/pipeline/fusion_driver.hpp"
#include "farlio/pipeline/odometry_output.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"

namespace farlio::pipeline {

enum class LatencyModel { Measured, Zero, Fixed };

struct ReplayOptions {
  LatencyModel latency = LatencyModel::Measured;
  double fixed_latency_s = 0.0;  ///< with LatencyModel::Fixed
  double added_delay_s = 0.0;    ///< added to every result's latency (latency sweeps)
};
/// Throws std::invalid_argument naming the option unless both latencies are in [0, kMaxDuration_s].
void validate_replay_options(const ReplayOptions& options);

class Odometry {
 public:
  /// `imu`: all samples of the recording (empty: LiDAR-only). Throws std::invalid_argument naming
  /// the field for an invalid config, gravity or options.
  Odometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2, std::vector<ImuSample> imu,
           const ReplayOptions& options = {});

  /// The body pose at the first scan in the world frame (default: the origin, yaw 0). Position
  /// and yaw are taken as given; roll and pitch too when LiDAR-only, while an inertial run takes
  /// them from gravity (the IMU measures them, as at the start of every run). Before the first
  /// scan only (throws std::logic_error after).
  void set_initial_pose(const SE3& body_pose);
  /// Localization in a prior map whose frame is the world frame (ScanPipeline::set_prior_map):
  /// pair with set_initial_pose where the run does not start where the mapping run started.
  void set_prior_map(std::vector<Eigen::Vector3f> world_points) { pipeline_.set_prior_map(std::move(world_points)); }

  /// Processes the next scan (scans must come in time order).
  OdometryFrame process(const Scan& scan);
  /// Advances the clock to stamp_ns (e.g. the end of the recording), emitting odometry.
  void finish(std::int64_t stamp_ns);

  /// Called for every 10 ms odometry sample (LIO) as the clock advances.
  std::function<void(const OdometrySample&)> on_odometry;

  [[nodiscard]] bool inertial() const { return driver_.inertial(); }
  /// What was tolerated since the last call (sorted IMU, an unusable IMU, a reset of the fusion).
  [[nodiscard]] std::vector<std::string> take_warnings();
  [[nodiscard]] const ScanPipeline& scan_pipeline() const { return pipeline_; }
  [[nodiscard]] std::optional<fusion::FusionStats> fusion_stats() const;
  /// The body pose the world frame starts from (roll and pitch from gravity when inertial, set
  /// at the first scan from the IMU samples up to its end).
  [[nodiscard]] const SE3& initial_body_pose() const { return initial_body_pose_; }

 private:
  void advance_clock(std::int64_t stamp_ns);
  [[nodiscard]] double latency_s(const FrameResult& r) const;
  /// Whether the scan arrives (at its end stamp) while the pipeline is busy and would wait too long.
  [[nodiscard]] bool dropped_as_busy(const Scan& scan, std::int64_t previous_end_ns) const;

  ReplayOptions options_;
  double max_wait_periods_;
  SE3 T_imu_lidar_, T_lidar_imu_;
  SE3 initial_body_pose_;
  std::optional<SE3> requested_initial_pose_;  ///< set_initial_pose
  std::vector<ImuSample> imu_;
  std::size_t next_imu_ = 0;
  FusionDriver driver_;
  ScanPipeline pipeline_;
  bool clock_started_ = false;
  std::int64_t clock_ns_ = 0;
  std::int64_t busy_until_ns_ = 0;
  std::int64_t last_scan_end_ns_ = 0;  ///< of the previous scan handed to process()
  std::vector<std::string> warnings_;
  FusionDriver::Samples outputs_;  ///< reused buffer of the odometry samples of one clock advance
};

}  // namespace farlio::pipeline
