#pragma once
// LiDAR-inertial odometry for a live robot: IMU samples and scans are pushed from any thread as
// they arrive, the scan pipeline runs on its own worker thread, and the fused 100 Hz odometry
// comes out through a callback. The logic between the scan pipeline and the fusion is the
// replay's (fusion_driver.hpp); only the clock differs: here time is the newest IMU stamp, and a
// scan's result is fused when its registration finishes, as a delayed measurement.
//
// Threads: add_imu() and add_scan() may be called from any threads (each kind in time order).
// on_odometry runs on the thread that called add_imu(); on_frame runs on the worker (or on the
// add_scan() caller for a dropped scan). Callbacks must not call back into the object.
// A scan that arrives while the worker is still busy waits in a slot of one, up to
// registration.max_wait_periods of its LiDAR period: a newer scan arriving meanwhile takes its
// place (the older is dropped), and one that waited longer is dropped when the worker comes to it.
// So a burst from the transport loses no scan and latency stays bounded; with 0 a scan arriving
// while busy is dropped at once (as in the paper), the rule of the replay (odometry.hpp). With
// fusion.enabled off, or until the first IMU sample arrives, the odometry is LiDAR-only and
// on_odometry is not called; the fusion takes over with the first scan after the first IMU
// sample (scans before it are registered, not fused; the world frame is then not gravity
// aligned, as in the replay). IMU samples that jump in time are handled by the driver
// (fusion_driver.hpp): no catch-up across a jump, no stamp emitted twice; take_warnings()
// reports what happened.
// With keep_registered_points, every processed frame carries its registered scan (world frame),
// for a live view; map_snapshot() copies the submap between two scans.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/types.hpp"
#include "farlio/fusion/sensor_fusion.hpp"
#include "farlio/map/map_snapshot.hpp"
#include "farlio/pipeline/fusion_driver.hpp"
#include "farlio/pipeline/odometry_output.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"

namespace farlio::pipeline {

class OnlineOdometry {
 public:
  using OdometryCallback = std::function<void(const OdometrySample&)>;
  using FrameCallback = std::function<void(const OdometryFrame&)>;

  OnlineOdometry(const Config& config, const SE3& T_imu_lidar, double gravity_m_s2, OdometryCallback on_odometry = {},
                 FrameCallback on_frame = {}, bool keep_registered_points = false);
  ~OnlineOdometry();
  OnlineOdometry(const OnlineOdometry&) = delete;
  OnlineOdometry& operator=(const OnlineOdometry&) = delete;

  /// The body pose at the first scan (Odometry::set_initial_pose) and a prior map to localize in
  /// (ScanPipeline::set_prior_map); before the first scan (std::logic_error after).
  void set_initial_pose(const SE3& body_pose);
  void set_prior_map(std::vector<Eigen::Vector3f> world_points);

  /// Feeds the fusion and emits the odometry for every 10 ms step up to the sample's stamp.
  void add_imu(const ImuSample& sample);
  /// Hands the scan to the worker (to wait for it when it is busy); false (and on_frame with the
  /// reason) when it is dropped at once. A scan that was waiting and is replaced gets on_frame
  /// with the reason here; one that waited too long, when the worker comes to it.
  bool add_scan(Scan scan);
  /// Blocks until the worker has finished every scan handed to it (the waiting one included).
  void wait_idle();
  /// Finishes the scan in progress and the one waiting, then ends the worker (also done by the
  /// destructor).
  void stop();

  /// Whether the fusion is in use: enabled, IMU samples have arrived, and the IMU was not found
  /// unusable (a silent accelerometer, a stuck gyro).
  [[nodiscard]] bool inertial() const;
  /// The warnings since the last call (a reset of the fusion, the gyro's unit, an unusable IMU).
  [[nodiscard]] std::vector<std::string> take_warnings();
  [[nodiscard]] std::optional<fusion::FusionStats> fusion_stats() const;
  /// Scans dropped because the worker was busy (at once, or replaced while waiting).
  [[nodiscard]] std::size_t scans_dropped_busy() const;
  /// The backend the scan pipeline runs on (chosen at construction) and why auto fell back to the
  /// CPU ('' when it did not).
  [[nodiscard]] Device device() const;
  [[nodiscard]] const std::string& device_message() const;
  /// A host copy of the submap (world frame); empty before the first scan. Waits for the scan in
  /// progress, if any.
  [[nodiscard]] map::MapSnapshot map_snapshot() const;

 private:
  void worker_loop();
  /// Counts the scan as dropped because the worker was busy and reports its frame.
  void drop_busy(const Scan& scan);
  OdometryFrame process(const Scan& scan);
  /// Whether time is the IMU's (the fusion runs and has samples), else the scan stamps'.
  [[nodiscard]] bool fused_clock() const;

  const Config config_;
  const SE3 T_imu_lidar_, T_lidar_imu_;
  const bool keep_registered_points_;
  OdometryCallback on_odometry_;
  FrameCallback on_frame_;

  // fusion state, guarded by state_mutex_
  mutable std::mutex state_mutex_;
  FusionDriver driver_;
  bool started_ = false;                       ///< the first scan has set the start pose
  std::optional<SE3> requested_initial_pose_;  ///< set_initial_pose
  std::size_t dropped_busy_ = 0;

  std::mutex emit_mutex_;  // keeps on_odometry calls in order

  // worker, guarded by queue_mutex_
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  using SteadyClock = std::chrono::steady_clock;
  std::optional<Scan> pending_;               ///< the scan the worker takes next
  SteadyClock::time_point pending_deadline_;  ///< dropped when the worker comes to it later
  std::int64_t last_added_end_ns_ = 0;        ///< end stamp of the previous scan handed in
  bool busy_ = false, stopping_ = false;      ///< busy: a scan is processed or waiting
  mutable std::mutex pipeline_mutex_;         // held by the worker while it processes, and by map_snapshot
  ScanPipeline pipeline_;                     // its backend made at construction; the start pose set at the first scan
  std::thread worker_;                        // last: started when everything above is constructed
};

}  // namespace farlio::pipeline
