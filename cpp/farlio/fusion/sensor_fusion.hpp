#pragma once
// The sensor-fusion front (paper Sec. "Sensor Fusion"): IMU samples in, LiDAR results in, the
// fused body odometry out. Deterministic and clock-free: time only advances through
// advance_to(), on a fixed grid of FusionConfig::step_s anchored at the initialisation stamp.
//
// Poses in and out are in the map frame of the scan pipeline, which need not be level (it is
// fixed at the first scan, while the body may already move). The filter is initialised from the
// LiDAR results of its first scans and the IMU between them (initialization.hpp): at rest as soon
// as two results show it, in motion once they span fusion.init.window_s; that alignment finds
// gravity in the map frame, and the EKF runs in the level frame it gives (z up), so that its
// gravity and reference angles hold. A re-initialisation after rejected results takes the
// velocity from the LiDAR results of the same window, with gravity already known.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"
#include "farlio/fusion/accel_unit_detector.hpp"
#include "farlio/fusion/delay_compensation.hpp"
#include "farlio/fusion/imu_buffer.hpp"
#include "farlio/fusion/imu_gate.hpp"
#include "farlio/fusion/imu_noise.hpp"
#include "farlio/fusion/initialization.hpp"
#include "farlio/fusion/innovation_stats.hpp"
#include "farlio/fusion/kinematic_ekf.hpp"
#include "farlio/fusion/reference_angles.hpp"
#include "farlio/fusion/standstill_bias.hpp"
#include "farlio/fusion/state_history.hpp"

namespace farlio::fusion {

struct BodyEstimate {
  bool valid = false;         ///< false before initialisation
  std::int64_t stamp_ns = 0;  ///< the filter time (the last step)
  SE3 pose;                   ///< body -> world
  Eigen::Vector3d velocity_body_m_s = Eigen::Vector3d::Zero();
};

struct FusionStats {
  std::int64_t steps = 0;
  std::int64_t lidar_groups_accepted = 0;  ///< position / orientation / velocity groups
  std::int64_t lidar_groups_rejected = 0;  ///< by the Mahalanobis gate
  std::int64_t lidar_too_old = 0;          ///< older than the state history: rejected
  std::int64_t reinitializations = 0;      ///< after max_consecutive_rejections
  InitializationReport initialization;     ///< how and when the filter was first initialised
  /// The up direction (against gravity) in the map frame as the filter now estimates it.
  Eigen::Vector3d up_map = Eigen::Vector3d::UnitZ();
  std::int64_t reference_angles_accepted = 0;
  std::int64_t reference_angles_rejected = 0;                 ///< gated or saturated
  std::int64_t imu_gaps = 0;                                  ///< gap events (each held-input stretch counts once)
  std::int64_t imu_samples_dropped = 0;                       ///< older than the newest sample
  std::int64_t imu_samples_rejected = 0;                      ///< by the gate (imu_gate.hpp)
  bool accel_in_g = false;                                    ///< the accelerometer was detected to report in g
  std::string accel_unit_message;                             ///< printable note when accel_in_g
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();  ///< standstill estimate + filter state
  Eigen::Vector3d accel_bias_m_s2 = Eigen::Vector3d::Zero();  ///< configured + filter state
  std::int64_t bias_samples = 0;
  std::string last_warning;  ///< the most recent warning, empty if none
  /// The IMU's noise measured on its samples (imu_noise.hpp), averaged over a filter step (largest
  /// axis; 0 before the first estimate), and its sample rate; the filter's input noise is the
  /// larger of this and fusion.gyro_input_std_rad_s / accel_input_std_m_s2.
  double measured_gyro_step_std_rad_s = 0.0;
  double measured_accel_step_std_m_s2 = 0.0;
  double imu_rate_hz = 0.0;
  /// The gyro's mean weight in the rotation rate that undistorts the scans, per LiDAR axis
  /// (deskew/rotation_rate_blend.hpp): 1 where the gyro's rate is used as measured, 0 where the
  /// LiDAR's constant twist; set by the driver that undistorts (pipeline/fusion_driver.hpp).
  Eigen::Vector3d deskew_gyro_weight = Eigen::Vector3d::Ones();
  /// The LiDAR updates' normalised innovations (innovation_stats.hpp), one entry per group fused:
  /// the pose (with the registration's covariance) or the position and orientation (the fixed
  /// noise), and the velocity.
  std::vector<InnovationStats> lidar_innovation;
};

/// Which groups of one LiDAR result were accepted.
struct LidarUpdateResult {
  bool position_accepted = false;
  bool orientation_accepted = false;
  bool velocity_accepted = false;   ///< false as well when no velocity was given
  bool initialized_filter = false;  ///< this result (re-)initialised the filter
  std::string rejection_reason;     ///< set when the whole result was rejected
};

/// Whether a body that moved by `motion` over dt_s stood: a displacement within
/// fusion.standstill.max_speed_m_s or the LiDAR's jitter (2 cm, or the larger rest jitter), and a
/// rotation within fusion.standstill.max_gyro_rad_s or the rest jitter's.
[[nodiscard]] bool moved_within_rest(const SE3& motion, double dt_s, const FusionConfig& config,
                                     const RestJitter& jitter);

class SensorFusion {
 public:
  /// `known`: what an earlier filter of the same run found of the map frame (its gravity, its
  /// window): the new one then needs no new alignment of gravity.
  SensorFusion(const FusionConfig& config, double gravity_m_s2, MapFrameKnowledge known = {});

  /// Any rate; a sample older than the newest one is dropped and counted.
  void add_imu(const ImuSample& sample);
  /// Steps the filter to stamp_ns (as many whole steps as fit). Before initialisation only the
  /// clock moves.
  void advance_to(std::int64_t stamp_ns);
  /// A LiDAR result for the scan-end stamp measured_at_ns, delivered at the current filter time
  /// (the difference is its delay); map_pose: the body pose in the map frame. Before the filter is initialised
  /// the results gather in the initialisation window until they initialise it.
  /// body_covariance: the registration's covariance of a right perturbation [t; r] of map_pose
  /// (registration/degeneracy.hpp); fused as one pose group when given and
  /// lidar_information_from_registration, else the fixed lidar_*_std apply. velocity_covariance:
  /// of the body velocity (lidar_measurement.hpp), used under the same condition; else
  /// lidar_velocity_std_m_s.
  LidarUpdateResult add_lidar(std::int64_t measured_at_ns, const SE3& map_pose,
                              const Eigen::Vector3d& body_velocity_m_s, bool use_velocity,
                              const std::optional<Mat6d>& body_covariance = std::nullopt,
                              const std::optional<Eigen::Matrix3d>& velocity_covariance = std::nullopt,
                              const RestJitter& rest_jitter = {});

  /// Starts the filter from a known state instead (another navigation system, a test): the body
  /// pose in a level map frame at stamp_ns and its velocity; the next LiDAR results update it.
  void initialize_known(std::int64_t stamp_ns, const SE3& body_pose, const Eigen::Vector3d& velocity_body_m_s);

  /// The map started again (after failures, or from the first scan at speed): the LiDAR results so
  /// far are not comparable with the next ones; the initialisation window starts again.
  void restart_window() { window_.clear(); }

  [[nodiscard]] bool initialized() const { return ekf_.initialized(); }
  /// Gravity in the map frame as now estimated, and the window, for a filter that takes over.
  [[nodiscard]] MapFrameKnowledge map_frame_knowledge() const;
  [[nodiscard]] const FusionConfig& config() const { return config_; }
  /// The filter's input noise over a step [accel (m/s^2), gyro (rad/s)]: the configured stds, or
  /// the IMU's noise measured on its samples where larger (imu_noise.hpp).
  [[nodiscard]] InputVector input_std() const { return ekf_.input_variance().cwiseSqrt(); }
  /// The IMU's noise measured on its samples (imu_noise.hpp); nullopt before the first estimate.
  [[nodiscard]] const std::optional<ImuNoise>& measured_imu_noise() const { return imu_noise_.noise(); }
  /// The filter step (FusionConfig::step_s) in ns.
  [[nodiscard]] std::int64_t step_ns() const { return step_ns_; }
  /// The filter's time: its newest step (valid once initialised).
  [[nodiscard]] std::int64_t time_ns() const { return time_ns_; }
  /// The current estimate, its pose in the map frame.
  [[nodiscard]] BodyEstimate estimate() const;
  /// The pose at stamp_ns as the filter now estimates it: the history's state plus the corrections
  /// applied since (as delay compensation shifts a past state), or predicted with the last input
  /// up to max_extrapolation_s beyond the newest step; nullopt otherwise.
  [[nodiscard]] std::optional<SE3> pose_at(std::int64_t stamp_ns) const;
  /// The body's rotation from start_ns to end_ns as the gyro integrates it (biases removed);
  /// nullopt where the IMU kept does not cover the interval or has a gap there.
  [[nodiscard]] std::optional<Eigen::Matrix3d> imu_rotation(std::int64_t start_ns, std::int64_t end_ns) const;
  /// The mean IMU input over [start_ns, end_ns] with the biases removed (the alignment's input);
  /// nullopt where the IMU kept does not cover the interval or has a gap there.
  [[nodiscard]] std::optional<ImuMean> imu_mean(std::int64_t start_ns, std::int64_t end_ns) const;
  /// The bias-corrected angular rate used in the last step (rad/s, body frame).
  [[nodiscard]] Eigen::Vector3d angular_velocity_body() const { return corrected_last_input().segment<3>(kGyroIndex); }
  [[nodiscard]] FusionStats stats() const;

 private:
  /// Adds a LiDAR result to the initialisation window (the last fusion.init.window_s of results; a gap
  /// longer than that starts it again).
  void add_to_window(std::int64_t stamp_ns, const SE3& body_pose, const RestJitter& rest_jitter);
  /// Initialises the filter from the window when its results allow (initialization.hpp); true if it did.
  bool initialize_from_window();
  /// Whether the window's results show the body at rest (between every two, a displacement within
  /// fusion.standstill.max_speed_m_s or the LiDAR's jitter, and a rotation within
  /// fusion.standstill.max_gyro_rad_s, each widened to the poses' RestJitter).
  [[nodiscard]] bool window_at_rest() const;
  /// The rotation from the filter's level frame to the map frame (the identity before gravity is known).
  [[nodiscard]] Eigen::Matrix3d map_from_level() const;
  /// A map-frame pose in the filter's level frame, and back.
  [[nodiscard]] SE3 to_level(const SE3& map_pose) const;
  [[nodiscard]] SE3 to_map(const SE3& level_pose) const;
  /// Starts the filter at a pose in its world frame; the tilt's std 0 holds it at zero. A
  /// re-initialisation keeps the biases and the tilt with their covariance.
  void initialize(std::int64_t stamp_ns, const SE3& level_pose, const Eigen::Vector3d& velocity_body_m_s,
                  double velocity_std_m_s, double tilt_std_rad);
  void step();
  [[nodiscard]] InputVector input_of(const ImuReading& r) const;
  /// The last input with the filter's bias estimates removed.
  [[nodiscard]] InputVector corrected_last_input() const { return corrected_input(ekf_.state(), last_input_); }
  void fuse_reference_angles(std::int64_t stamp_ns);
  [[nodiscard]] int spread_steps(std::int64_t measured_at_ns) const;
  [[nodiscard]] double gate(int dim) const;
  /// Adds a LiDAR group's NIS to its InnovationStats.
  void record_innovation(MeasurementKind kind, int dim, double nis);
  void warn(std::string message);
  /// Adds x_after - x_before (angles wrapped) to the cumulative correction.
  void record_correction(const StateVector& before);

  FusionConfig config_;
  double gravity_m_s2_;
  std::int64_t step_ns_;
  KinematicEkf ekf_;
  ImuBuffer imu_;
  ImuGate imu_gate_;
  AccelUnitDetector accel_unit_;
  StandstillGyroBias bias_;
  ImuNoiseMeter imu_noise_;
  ReferenceAngleEstimator reference_;
  StateHistory history_;
  SpreadMeasurementQueue queue_;
  Eigen::Vector3d accel_bias_m_s2_;
  std::int64_t time_ns_ = 0;   ///< filter time (valid once initialised)
  std::int64_t clock_ns_ = 0;  ///< the latest advance_to stamp
  bool clock_set_ = false;
  bool in_gap_ = false;
  std::optional<std::int64_t> last_lidar_ns_;
  int consecutive_rejections_ = 0;
  InputVector last_input_ = InputVector::Zero();
  std::vector<WindowPose> window_;                 ///< the initialisation window (map frame)
  std::optional<Eigen::Matrix3d> level_from_map_;  ///< set by the first initialisation
  double known_tilt_std_rad_ = 0.0;                ///< with level_from_map_ given at construction
  StateVector cumulative_correction_ = StateVector::Zero();
  FusionStats stats_;
};

}  // namespace farlio::fusion
