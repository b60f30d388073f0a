#pragma once
// The sequence generator: LiDAR scans and IMU samples of one profile with exact ground truth,
// all in memory (writing files is the sequence-folder writer's job).
//
// Scan i covers [start + i * period, start + (i + 1) * period). Time t of the sequence is time
// t + motion_start_s of the profile's motion (0: the profile's start, at rest). Every point is the hit of a
// ray fired at its own instant t, expressed in the LiDAR frame at t:
//   point = inverse(T_world_body(t) * T_imu_lidar) * hit, time_s = t - scan start.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "farlio/core/trajectory.hpp"
#include "farlio/core/types.hpp"
#include "farlio/sim/config.hpp"
#include "farlio/sim/motion.hpp"
#include "farlio/sim/world.hpp"

namespace farlio::sim {

class SequenceGenerator {
 public:
  explicit SequenceGenerator(const SimConfig& config);

  /// Scans whose end lies within the duration.
  [[nodiscard]] std::size_t num_scans() const;
  /// Deterministic from (seed, i): the same result in any call order; thread-safe. Rays of a
  /// scan are cast in parallel with TBB (the result does not depend on the thread count).
  [[nodiscard]] Scan scan(std::size_t i) const;
  /// `scan` (one of scan(i)) as KITTI stores its scans: every point moved with the exact motion into
  /// the LiDAR frame at the scan end, no per-point times, both stamps the end stamp.
  [[nodiscard]] Scan motion_compensated(const Scan& scan) const;
  /// All samples over [0, duration], time-ordered, noisy unless noise_free.
  [[nodiscard]] std::vector<ImuSample> imu() const;
  /// The exact state of the body at stamp_ns.
  [[nodiscard]] BodyState state(std::int64_t stamp_ns) const;
  /// Body poses at start + k / rate_hz over [0, duration].
  [[nodiscard]] Trajectory groundtruth_body(double rate_hz) const;
  /// Body poses at every scan end stamp.
  [[nodiscard]] Trajectory groundtruth_scans() const;

  [[nodiscard]] SE3 T_imu_lidar() const { return world_->T_imu_lidar; }
  [[nodiscard]] double lidar_rate_hz() const { return config_.lidar_rate_hz; }
  [[nodiscard]] double imu_rate_hz() const { return config_.imu_rate_hz; }
  [[nodiscard]] double gravity_m_s2() const { return config_.gravity_m_s2; }
  /// Profile, seed, duration, rates, speeds, path length, noise ... (for meta.yaml).
  [[nodiscard]] std::map<std::string, std::string> description() const;

  [[nodiscard]] const SimConfig& config() const { return config_; }
  [[nodiscard]] const Scene& scene() const { return world_->scene; }
  [[nodiscard]] const std::vector<LidarSensor>& lidars() const { return world_->lidars; }
  /// Scan period in ns (rounded to whole ns).
  [[nodiscard]] std::int64_t scan_period_ns() const { return period_ns_; }
  [[nodiscard]] std::int64_t scan_start_ns(std::size_t i) const;
  /// Seconds since the sequence start of a stamp.
  [[nodiscard]] double seconds_since_start(std::int64_t stamp_ns) const;

 private:
  SimConfig config_;
  std::shared_ptr<const World> world_;
  /// The world's motion from config_.motion_start_s on: state(t) is the world's at t + motion_start_s.
  std::shared_ptr<const MotionModel> motion_;
  std::int64_t period_ns_ = 0;
};

}  // namespace farlio::sim
