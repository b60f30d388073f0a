#pragma once
// What the LiDAR-inertial odometry reports: one OdometryFrame per scan (what happened to it) and
// one OdometrySample per fusion step (the 100 Hz output). The replay (odometry.hpp) and the
// online odometry (online_odometry.hpp) report the same types.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "farlio/registration/degeneracy.hpp"

namespace farlio::pipeline {

/// What happened to one scan.
struct OdometryFrame {
  FrameResult scan;                   ///< the scan pipeline's result (LiDAR pose, timings, ...)
  SE3 body_pose;                      ///< registered body pose at the scan end
  bool processed = false;             ///< false: dropped before registration (pipeline busy)
  bool fused = false;                 ///< the result reached the fusion
  std::string drop_reason;            ///< why it was not processed or not fused
  std::int64_t started_ns = 0;        ///< when the pipeline started on it (the odometry's clock)
  std::int64_t available_ns = 0;      ///< when its result reached the fusion
  bool guess_from_fusion = false;     ///< initial guess and undistortion came from the fusion
  bool guess_turned_by_gyro = false;  ///< the guess turned as the gyro did (the fusion's, or the one before the filter)
  /// How well the registration constrained the body pose (registered scans only).
  std::optional<registration::Degeneracy> degeneracy;
  /// The registered scan: the kept (undistorted, downsampled) points in the world frame at the
  /// registered pose. Filled only by the online odometry when asked to (keep_registered_points).
  std::vector<Eigen::Vector3f> registered_points;
};

/// One sample of the 100 Hz odometry output.
struct OdometrySample {
  std::int64_t stamp_ns = 0;
  SE3 body_pose;
  Eigen::Vector3d velocity_body_m_s = Eigen::Vector3d::Zero();
};

/// How long (ns) a scan ending at end_ns may wait for a busy pipeline: max_wait_periods
/// (registration.max_wait_periods) of the time since the previous scan's end; <= 0: not at all.
/// The one rule of the replay and the online odometry.
inline double busy_wait_limit_ns(double max_wait_periods, std::int64_t end_ns, std::int64_t previous_end_ns) {
  return max_wait_periods * static_cast<double>(end_ns - previous_end_ns);
}

/// The frame of a scan that arrived while the scan pipeline was still busy with the previous one
/// (dropped unprocessed, as in the paper).
inline OdometryFrame busy_frame(const Scan& scan) {
  OdometryFrame frame;
  frame.scan.stamp_ns = scan.end_stamp_ns;
  frame.drop_reason = "the pipeline was still busy with the previous scan";
  return frame;
}

}  // namespace farlio::pipeline
