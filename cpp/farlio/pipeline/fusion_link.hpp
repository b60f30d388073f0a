#pragma once
// The two places where the scan pipeline and the sensor fusion meet (paper Fig. 2), shared by the
// deterministic replay (odometry.hpp) and the threaded online odometry (online_odometry.hpp):
//   before a scan: the fusion's pose at the scan end is the initial guess, and a regression over
//     its pose history during the scan is the motion for the undistortion;
//   after a scan: the registered body pose and the eq. (6) velocity go into the fusion as a
//     (possibly delayed) measurement, unless the frame is to be dropped.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/core/trajectory.hpp"
#include "farlio/core/types.hpp"
#include "farlio/deskew/scan_motion.hpp"
#include "farlio/fusion/sensor_fusion.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"

namespace farlio::pipeline {

/// Roll and pitch that make the mean specific force of the first samples (the first
/// kGravityAlignmentWindow_s, and none after until_ns: the first scan's end) point up; yaw 0.
/// Identity without samples.
SE3 gravity_aligned_start(const std::vector<ImuSample>& imu, std::int64_t until_ns);
/// Samples that gravity_aligned_start averages: those within this window of the first.
inline constexpr double kGravityAlignmentWindow_s = 0.2;

/// What the fusion tells the scan pipeline about a scan; empty before the filter is initialised.
struct ScanPrior {
  std::optional<SE3> guess;                  ///< LiDAR pose at the scan end
  std::optional<deskew::ScanMotion> motion;  ///< LiDAR motion during the scan
};
ScanPrior prior_from_fusion(const fusion::SensorFusion& fusion, const Scan& scan, const SE3& T_imu_lidar);

/// Why a scan's result must not reach the fusion; empty when it may.
std::string drop_reason(const FrameResult& result, bool map_started);

/// Fuses a registered body pose for the scan end stamp_ns with the eq. (6) velocity from the
/// previous registered body pose (when there is one and it is older).
void fuse_scan(fusion::SensorFusion& fusion, std::int64_t stamp_ns, const SE3& body_pose,
               const std::optional<StampedPose>& previous);

}  // namespace farlio::pipeline
