#pragma once
// Initialising the filter at any instant of any motion, from the LiDAR poses of its first scans
// (LiDAR-only odometry) and the IMU between them: the LiDAR-inertial alignment of a window.
//
// Between two LiDAR poses k and k+1 (map frame, dt apart) the IMU, integrated in the body frame
// at k (rotation dR, velocity increment beta, position increment alpha), ties the unknown map-frame
// velocities v_k and the unknown gravity vector g of the map frame (VINS-Mono's linear alignment):
//   p_{k+1} - p_k - R_k alpha_k = v_k dt + g dt^2 / 2
//   v_{k+1} - v_k - g dt        = R_k beta_k
// All v_k and g follow by linear least squares (3 poses or more), then g is held at its known
// magnitude and the velocities solved again. At rest the same equations give g from the
// specific force (levelling) with v = 0; a zero-velocity prior lets two poses suffice there. With
// gravity known (a re-initialisation: the map frame has not changed), two poses give the velocities.
// The map frame need not be level: the filter works in the level frame that `level_from_map`
// gives (sensor_fusion.hpp).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio::fusion {

/// A pose's jitter at rest beyond the LiDAR's usual 2 cm (SensorFusion::add_lidar): a degenerate
/// scan's own stds along its worst translation and rotation, which the caller passes only where
/// the IMU reads rest too (a narrow field of view standing: FusionDriver); 0 otherwise.
struct RestJitter {
  double translation_m = 0.0;
  double rotation_rad = 0.0;
};

/// A LiDAR result the window holds: the body pose in the map frame at its scan end.
struct WindowPose {
  std::int64_t stamp_ns = 0;
  SE3 body_pose;
  RestJitter rest_jitter;  ///< how far it may jitter at rest beyond the usual
};

/// The IMU over [start_ns, end_ns] as the alignment reads it: the mean specific force (m/s^2) and
/// angular rate (rad/s, biases removed); nullopt where the IMU has a gap.
struct ImuMean {
  Eigen::Vector3d accel_m_s2;
  Eigen::Vector3d gyro_rad_s;
};
using ImuMeanFn = std::function<std::optional<ImuMean>(std::int64_t start_ns, std::int64_t end_ns)>;

/// The IMU's motion between two stamps in the body frame at the first: rotation, velocity and
/// position increments without gravity (rotated into the map by the pose at the first stamp).
struct ImuIncrement {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double dt_s = 0.0;
};
/// Integrates the IMU over [start_ns, end_ns] in sub-steps of at most step_ns (each with the mean
/// input over it); nullopt when the IMU has a gap there.
std::optional<ImuIncrement> integrate_imu(const ImuMeanFn& imu, std::int64_t start_ns, std::int64_t end_ns,
                                          std::int64_t step_ns);

struct AlignmentOptions {
  double gravity_m_s2 = 9.81;
  /// Gravity in the map frame when it is known (a re-initialisation); else it is estimated.
  std::optional<Eigen::Vector3d> gravity_map_m_s2;
  /// A prior v = 0 on every pose with this std (m/s): the LiDAR showed the body at rest.
  std::optional<double> zero_velocity_std_m_s;
  std::int64_t step_ns = 10'000'000;  ///< IMU integration sub-step
};

/// What the alignment of a window found.
struct Alignment {
  Eigen::Vector3d gravity_map_m_s2 = Eigen::Vector3d::Zero();  ///< at the known magnitude
  Eigen::Vector3d velocity_map_m_s = Eigen::Vector3d::Zero();  ///< at the window's last pose
  /// | |g| estimated freely - g | / g: how far the window's data are from consistent (0 when gravity
  /// was given or held by the zero-velocity prior alone)
  double gravity_norm_error = 0.0;
  /// RMS of the position equations' residuals after the fit (m)
  double position_residual_m = 0.0;
};

/// The alignment of `poses` (time order, two at least) with the IMU; nullopt when the IMU has a
/// gap in the window or the system is not determined.
std::optional<Alignment> align_window(const std::vector<WindowPose>& poses, const ImuMeanFn& imu,
                                      const AlignmentOptions& options);

/// The rotation that turns the map frame so that `gravity_map` points along -z (the smallest
/// such rotation: no turn about the vertical).
Eigen::Matrix3d level_from_map(const Eigen::Vector3d& gravity_map);

/// What a filter knows of the map frame, which outlives it when the fusion starts again (a new
/// filter after a jump of the IMU clock or a change of the gyro's unit): gravity in the map frame,
/// how well it is known, and the LiDAR results of the initialisation window.
struct MapFrameKnowledge {
  std::optional<Eigen::Vector3d> gravity_map_m_s2;  ///< unset before the first initialisation
  double tilt_std_rad = 0.0;                        ///< of gravity's direction
  std::vector<WindowPose> window;
};

/// How the filter was initialised, for summary.json and the logs.
struct InitializationReport {
  bool initialized = false;
  std::string mode;           ///< "standstill", "in motion", "given" (initialize_known), or "" before
  std::int64_t stamp_ns = 0;  ///< of the LiDAR result that initialised it
  int window_poses = 0;       ///< LiDAR poses aligned
  double window_s = 0.0;      ///< their time span
  double speed_m_s = 0.0;     ///< the speed found
  Eigen::Vector3d up_map = Eigen::Vector3d::UnitZ();  ///< the up direction (against gravity) in the map frame
  double map_tilt_deg = 0.0;                          ///< angle between the map frame's z and up
  double gravity_norm_error = 0.0;                    ///< Alignment::gravity_norm_error
};

}  // namespace farlio::fusion
