#pragma once
// Where the scan pipeline and the sensor fusion meet (paper Fig. 2): one object that both the
// deterministic replay (odometry.hpp) and the threaded online odometry (online_odometry.hpp)
// drive, so that the two cannot drift apart. They differ only in their clock: the replay feeds the
// recording's IMU up to a simulated time, the online odometry each sample as it arrives.
//   the fusion clock: IMU samples in, the EKF stepped, one odometry sample every fusion.step_s,
//     each computed from the IMU samples around its instant (interpolated); the filter steps only
//     as far as the newest sample while the next is due (fusion.imu_gate.gap_limit_s), and a LiDAR
//     result ahead of it waits until the filter has passed its stamp;
//   before a scan: the start pose (roll and pitch from gravity when the first IMU samples look
//     unaccelerated) at the first scan, the fusion's pose at the scan end as the initial guess,
//     and a regression over its pose history during the scan as the motion for the undistortion;
//   after a scan: the drop rules, the registration's covariance in the body frame and its
//     degeneracy, then the registered body pose and the eq. (6) velocity go into the fusion as a
//     (possibly delayed) measurement with that covariance.
// Without the fusion (LiDAR-only odometry) the clock is idle, the prior is empty and nothing is
// fused; the drop rules still apply.
// What the driver does not let through (docs/hardening.md, "Configuration and clocks"), each with a
// warning (take_warnings):
//   a sample stamped more than fusion.imu_gate.max_bridged_gap_s from the newest (a far-future stamp, a
//     stamp far back) waits for the next: if that one follows the newest, the stamp alone was
//     wrong and the sample is dropped; if it follows the held one, the IMU clock jumped: the
//     fusion is reset and starts again from the next LiDAR results, so that no catch-up loop runs
//     across the jump; a sample older than the newest within the gap is dropped, and no odometry
//     stamp is emitted twice;
//   a LiDAR result older than the IMU clock by more than fusion.imu_gate.max_bridged_gap_s does not
//     initialise the filter (the IMU and LiDAR clocks differ);
//   a gyro in deg/s is scaled (the fusion starts again), a stuck gyro or a silent accelerometer
//     ends the fusion (LiDAR-only): fusion/gyro_unit_detector.hpp; a unit still undecided after
//     kUndecidedGyroWarning_s of scans is a warning;
//   a result more than fusion.imu_gate.max_bridged_gap_s after the newest IMU sample (the IMU
//     stopped) is not fused, with that drop reason; one less far waits for the IMU to cover it;
//   results before the first IMU sample are not fused (no IMU yet: LiDAR-only until it comes),
//     with that drop reason and one warning;
//   a result with a degenerate translation does not initialise the filter (its pose says nothing
//     of the velocity along that direction): it restarts the initialisation window, with that drop
//     reason, and after kDegenerateStartWarning_s of them without a filter, one warning; unless it
//     stands within its own stds while an IMU no noisier than the configured input noise reads
//     gravity alone, after a scan that constrains every direction stood so and with every scan
//     since standing (a narrow field of view on the grid): then it enters the window with its stds
//     as its rest jitter, and the filter starts at rest.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/trajectory.hpp"
#include "farlio/core/types.hpp"
#include "farlio/deskew/rotation_rate_blend.hpp"
#include "farlio/deskew/scan_motion.hpp"
#include "farlio/fusion/gyro_unit_detector.hpp"
#include "farlio/fusion/sensor_fusion.hpp"
#include "farlio/pipeline/odometry_output.hpp"

namespace farlio::pipeline {

/// The map frame's attitude at the first scan: roll and pitch that make the mean specific force of
/// the first samples (the first kGravityAlignmentWindow_s, and none after until_ns: the first
/// scan's end) point up, yaw 0, when those samples look unaccelerated (their mean within
/// kLevelledStartMaxAccelDeviation_m_s2 of gravity and their mean rate below max_gyro_rad_s: at
/// rest, or at a constant velocity); else, and without samples, the identity (the body's own
/// attitude). The fusion finds gravity in that frame either way (fusion/initialization.hpp).
SE3 gravity_aligned_start(const std::vector<ImuSample>& imu, std::int64_t until_ns, double gravity_m_s2,
                          double max_gyro_rad_s);
/// Samples that gravity_aligned_start averages: those within this window of the first.
inline constexpr double kGravityAlignmentWindow_s = 0.2;
/// A start levelled by a mean specific force this close to gravity is off the vertical by at most
/// about atan(sqrt(2 g d) / g): 14 deg (a horizontal acceleration of 2.4 m/s^2).
inline constexpr double kLevelledStartMaxAccelDeviation_m_s2 = 0.3;

/// What the fusion tells the scan pipeline about a scan: from the filter once it is initialised;
/// before, the constant-velocity translation with the gyro's rotation (not fused: the pipeline
/// registers it as LiDAR-only); empty without a usable gyro.
struct ScanPrior {
  std::optional<SE3> guess;                  ///< LiDAR pose at the scan end
  std::optional<deskew::ScanMotion> motion;  ///< LiDAR motion during the scan
  bool fused = false;                        ///< from the filter
  bool confirmed = false;                    ///< fused, with the gyro's unit decided against the LiDAR
};

/// `scan` registered by `pipeline` from `prior` into `out`: the pipeline's result, the body pose
/// (T_lidar_imu at the LiDAR pose), processed, and where the guess came from (which the gyro's
/// unit check reads). The replay (Odometry) and the online odometry both register this way.
void register_from_prior(ScanPipeline& pipeline, const Scan& scan, const ScanPrior& prior, const SE3& T_lidar_imu,
                         OdometryFrame& out);

/// A LiDAR result for the fusion (FusionDriver::link): the body pose at the scan end, its
/// registration covariance, and the velocity from the previous result (eq. 6).
struct PendingResult {
  std::int64_t stamp_ns = 0;
  SE3 body_pose;
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  bool has_velocity = false;
  std::optional<Mat6d> covariance;
  std::optional<Eigen::Matrix3d> velocity_covariance;
  fusion::RestJitter rest_jitter;  ///< a degenerate scan at rest: its own stds (SensorFusion::add_lidar)
};

/// Why a scan's result must not reach the fusion; empty when it may.
std::string drop_reason(const FrameResult& result, bool map_started);

class FusionDriver {
 public:
  using Samples = std::vector<OdometrySample>;

  /// With `inertial` false the driver runs LiDAR-only (no fusion). Throws std::invalid_argument
  /// naming the field when the config is invalid (validate_config) or gravity is not a magnitude
  /// near Earth's (validate_gravity).
  FusionDriver(const Config& config, double gravity_m_s2, const SE3& T_imu_lidar, bool inertial);

  /// Feeds one IMU sample (in time order): appends to `out` the odometry sample of every output
  /// instant before the sample's stamp, then of the one at its stamp (each stamp once).
  void add_imu(const ImuSample& sample, Samples& out);
  /// Moves the fusion clock to stamp_ns without new IMU data, appending the odometry samples up
  /// to it (the replay, past the last sample it has fed); the fusion predicts at most
  /// fusion.imu_gate.max_bridged_gap_s beyond the newest sample.
  void advance_to(std::int64_t stamp_ns, Samples& out);
  /// Runs LiDAR-only from now on.
  void stop_fusion() { fusion_.reset(); }
  /// The warnings since the last call (a reset of the fusion, the gyro's unit, an unusable IMU).
  [[nodiscard]] std::vector<std::string> take_warnings() { return std::exchange(warnings_, {}); }
  /// fusion.imu_gate.max_bridged_gap_s: the largest jump of the IMU clock the fusion bridges.
  [[nodiscard]] double max_bridged_gap_s() const { return fusion_config_.imu_gate.max_bridged_gap_s; }

  [[nodiscard]] bool inertial() const { return fusion_.has_value(); }
  /// Whether an IMU sample has been fed.
  [[nodiscard]] bool has_imu() const { return !startup_imu_.empty(); }
  /// The newest IMU stamp fed, or the latest advance_to stamp (0 before either).
  [[nodiscard]] std::int64_t clock_ns() const { return clock_ns_; }
  /// The body pose the world frame starts from, for a first scan ending at first_scan_end_ns:
  /// roll and pitch from gravity when inertial and unaccelerated (gravity_aligned_start), else the
  /// identity.
  /// With `requested` (a body pose the user gives, e.g. in a prior map): its position and yaw, and
  /// its roll and pitch too when there is no fusion (with one, the IMU measures them).
  [[nodiscard]] SE3 start_pose(std::int64_t first_scan_end_ns,
                               const std::optional<SE3>& requested = std::nullopt) const;

  /// The initial guess and the motion during the scan (ScanPrior); lidar_twist: the scan
  /// pipeline's constant-velocity twist (ScanPipeline::last_twist), for the translation before
  /// the filter is initialised and, once measured (twist_measured: two scans registered), for the
  /// rotation rate of the undistortion, blended with the gyro's by their errors
  /// (deskew/rotation_rate_blend.hpp).
  [[nodiscard]] ScanPrior prior(const Scan& scan, const registration::Vec6d& lidar_twist, bool twist_measured);
  /// After the scan pipeline (frame.scan and frame.body_pose set): sets frame.drop_reason and
  /// frame.degeneracy and, unless dropped and when inertial, fuses the result at the current clock
  /// (frame.fused).
  void link(const Scan& scan, OdometryFrame& frame);

  [[nodiscard]] std::optional<fusion::FusionStats> stats() const;

 private:
  /// Steps the filter to the next output instant and appends its estimate.
  void emit_step(Samples& out);
  /// A new filter (not initialised) fed with `samples`, with what the old one knew of the map
  /// frame; the output grid is kept unless `regrid`.
  void restart_fusion(const std::deque<ImuSample>& samples, bool regrid);
  /// Whether `sample` may reach the fusion: false for a sample older than the newest (dropped)
  /// and for a silent accelerometer.
  bool admit(const ImuSample& sample);
  /// The sample through admit into the fusion, emitting the odometry up to its stamp.
  void feed_imu(const ImuSample& sample, Samples& out);
  /// How far stamp_ns lies after the newest IMU sample (s; negative before it, 0 before the first
  /// sample).
  [[nodiscard]] double after_newest_imu_s(std::int64_t stamp_ns) const;
  /// The IMU clock jumped to `sample`: the fusion is reset there.
  void jump_clock(const ImuSample& sample);
  /// After the gyro unit was decided: scales and restarts, or ends the fusion.
  void apply_gyro_unit();
  /// The rotation part of `motion` (the fusion's over the scan; before the filter, the gyro's
  /// least-squares line) blended with lidar_twist's by their errors (unchanged before the filter
  /// across an IMU gap).
  void blend_rotation_rate(const Scan& scan, const registration::Vec6d& lidar_twist, deskew::ScanMotion& motion);
  /// Whether the registration held the frame's degenerate directions at the fusion's prior.
  [[nodiscard]] bool held_at_prior(const OdometryFrame& frame) const;
  /// The registration's pose covariance in the body frame (its degenerate rotation axes released
  /// when the registration held them); sets frame.degeneracy. nullopt without a registered scan.
  [[nodiscard]] std::optional<Mat6d> registration_covariance(OdometryFrame& frame) const;
  /// The body pose fused for the frame: the registered one, moved along degenerate translations the
  /// registration held by the step the scan gives there (registration::degenerate_translation_step).
  [[nodiscard]] SE3 measured_body_pose(const OdometryFrame& frame) const;
  /// While the gyro's unit is undecided: compares the gyro's rotation with the LiDAR's over the
  /// last scan interval (scans with a degenerate direction left out) and applies a decision.
  void compare_gyro_unit(std::int64_t stamp_ns, const OdometryFrame& frame);
  /// Hands the detector the intervals the IMU now covers (compare_gyro_unit queues them).
  void compare_covered_rotations();
  /// One warning once the unit is still undecided kUndecidedGyroWarning_s after the first comparison.
  void warn_undecided_gyro(std::int64_t stamp_ns);
  /// Before the filter: a scan with a degenerate translation restarts the initialisation window and
  /// is not fused (with a warning once such scans have held the start for a while).
  /// A degenerate scan that stands as the IMU does, after a scan that constrains every direction
  /// stood and with every scan since standing, passes, with its stds as its rest jitter.
  void hold_start_at_degenerate_scan(std::int64_t stamp_ns, const SE3& measured, OdometryFrame& frame,
                                     fusion::RestJitter& rest_jitter);
  /// Whether a scan and the IMU since the last scan show rest: the scan moved within its own stds
  /// and the IMU read gravity alone, unturned (within its measured noise, once measured).
  [[nodiscard]] bool scan_stands(std::int64_t stamp_ns, const SE3& measured, const fusion::RestJitter& own_stds) const;
  /// Whether the IMU's noise is measured and within fusion.gyro_input_std_rad_s / accel_input_std_m_s2.
  [[nodiscard]] bool imu_within_configured_noise() const;
  /// Fuses `result` now, or once the IMU reaches its stamp (a LiDAR result ahead of the newest
  /// IMU sample waits: the filter predicts only with inputs it has).
  void fuse_when_covered(PendingResult result);
  /// Fuses the waiting results that the IMU now covers, up to `horizon_ns`.
  void fuse_covered(std::int64_t horizon_ns);
  /// How far the filter may step for a clock at `stamp_ns`: the newest IMU sample while the next one
  /// is not overdue (fusion.imu_gate.gap_limit_s); across a gap, up to max_bridged_gap_s past it.
  [[nodiscard]] std::int64_t fusion_horizon(std::int64_t stamp_ns) const;
  /// Whether stamp_ns lies more than fusion.imu_gate.max_bridged_gap_s after the newest IMU sample
  /// (a result there is not fused: the filter cannot reach it).
  [[nodiscard]] bool beyond_bridged_gap(std::int64_t stamp_ns) const;
  /// The sample with its gyro in rad/s.
  [[nodiscard]] ImuSample in_si_units(const ImuSample& sample) const;
  void warn(std::string message);

  RegistrationConfig registration_config_;
  FusionConfig fusion_config_;
  double gravity_m_s2_;
  std::int64_t max_bridged_gap_ns_;
  SE3 T_imu_lidar_;
  std::optional<fusion::SensorFusion> fusion_;
  fusion::GyroUnitDetector gyro_unit_;
  std::vector<ImuSample> startup_imu_;         ///< the first kGravityAlignmentWindow_s, for the start pose
  std::vector<Eigen::Vector3d> first_accels_;  ///< for the silent accelerometer check
  std::deque<ImuSample> recent_imu_;           ///< raw, the last history_s, re-fed when the gyro's unit changes
  std::optional<std::int64_t> newest_imu_ns_;
  std::optional<ImuSample> held_jump_;             ///< a sample beyond the bridged gap, until the next one
  bool warned_no_imu_ = false;                     ///< a scan came before the first IMU sample
  std::optional<std::int64_t> first_compared_ns_;  ///< the first scan the gyro's unit was compared at
  bool gyro_follows_lidar_ = false;                ///< the gyro turned as the LiDAR between the last two scans compared
  bool gyro_turn_confirmed_ = false;  ///< a clear turn agreed with the gyro, and no interval since disagreed
  bool warned_undecided_gyro_ = false;
  std::optional<std::int64_t> first_degenerate_start_ns_;  ///< the first degenerate scan before the filter
  deskew::RotationRateBlend rotation_rate_blend_;
  Eigen::Vector3d gyro_weight_sum_ = Eigen::Vector3d::Zero();  ///< over the blended scans, for stats()
  std::int64_t blended_scans_ = 0;
  bool warned_degenerate_start_ = false;
  bool rest_seen_by_constrained_scan_ = false;  ///< since then, every scan stood (scan_stands)
  std::int64_t clock_ns_ = 0;
  std::int64_t next_output_ns_ = 0;  ///< 0: set by the first IMU sample
  std::optional<std::int64_t> last_output_ns_;
  std::optional<StampedPose> last_body_;  ///< the previous processed scan's body pose
  std::optional<Mat6d> last_covariance_;  ///< and its registration covariance
  /// A LiDAR rotation between two scans, for the gyro unit detector once the IMU covers it.
  struct PendingRotation {
    std::int64_t start_ns = 0;
    std::int64_t end_ns = 0;
    Eigen::Vector3d lidar_rotation = Eigen::Vector3d::Zero();
    bool constrained = true;      ///< the later scan constrains every direction: the unit is judged on it
    bool lidar_own_guess = true;  ///< the later scan was registered from a guess the gyro did not turn
  };
  std::deque<PendingRotation> pending_rotations_;
  /// gyro_follows_lidar_ and gyro_turn_confirmed_ from one interval's rotations (gyro: nullopt
  /// where the IMU does not cover it).
  void compare_gyro_turn(const std::optional<Eigen::Matrix3d>& gyro_rotation, const PendingRotation& r);
  std::deque<PendingResult> pending_;  ///< LiDAR results ahead of the newest IMU sample
  std::vector<std::string> warnings_;
};

}  // namespace farlio::pipeline
