#pragma once
// The one parameter set of farlio. Every field has its unit in its name, a documented default and
// a valid range; the defaults serve every sensor and dataset (one parameter set, as in the paper).
// YAML files and command-line overrides map onto the fields by their dotted names (e.g.
// `map.voxel_size_m`); a run writes the full effective config next to its outputs; `farlio config`
// prints every field with its default, range and meaning.
//
// Each section is one list, the only place a field is written down:
//   FIELD(type, name, default, valid range (config_range.hpp), documentation)
// The list declares the struct's members with their defaults (below) and gives config_fields.cpp
// the dotted names, the documentation and the validation. A section may hold sub-sections, each
// its own list and struct, named one level deeper (`fusion.reference_angles.roll_std_rad`).
#include <cstdint>

#include "farlio/core/config_range.hpp"
#include "farlio/core/device.hpp"

namespace farlio {

/// The k-NN buffers hold this many neighbours at most (map.covariance_neighbors' upper bound).
inline constexpr int kMaxCovarianceNeighbors = 32;
/// Voxels are indexed by int32 in the pool.
inline constexpr double kMaxVoxelCapacity = 2147483647.0;
// Upper bounds of the config fields (config_range.hpp): far beyond any sensor or platform, so that
// only typos and unit mistakes are refused.
/// Distances from the sensor (ranges, radii): 10 km, beyond any LiDAR.
inline constexpr double kMaxDistance_m = 1e4;
/// Voxel edges: 21-bit voxel keys hold +-2^20 voxels, +-10 km at the smallest voxel.
inline constexpr double kMinVoxelSize_m = 0.01;
inline constexpr double kMaxVoxelSize_m = 100.0;
/// Points per voxel (the pool allocates this many slots per voxel).
inline constexpr double kMaxPointsPerVoxel = 1000.0;
/// Dimensionless ratios, factors and chi-square gates.
inline constexpr double kMaxRatio = 1e6;
/// Counts of iterations, samples, steps or taps.
inline constexpr double kMaxCount = 1e6;
/// Standard deviations, thresholds and rates in SI units (m, rad, m/s, rad/s, m/s^2).
inline constexpr double kMaxSiValue = 1e3;
/// Durations in s (the fusion keeps history_s / step_s states; stamps are int64 ns).
inline constexpr double kMaxDuration_s = 60.0;
/// Constant IMU biases: beyond these it is not a bias but a wrong unit or axis.
inline constexpr double kMaxGyroBias_rad_s = 1.0;
inline constexpr double kMaxAccelBias_m_s2 = 5.0;
/// CPU threads of one pipeline.
inline constexpr double kMaxThreads = 1024.0;

// ---- preprocess: range crop of each incoming scan ----------------------------------------------
#define FARLIO_PREPROCESS_FIELDS(FIELD)                                           \
  FIELD(double, min_range_m, 1.0, range::non_negative_up_to(kMaxDistance_m),      \
        "points closer than this to the sensor are dropped (the vehicle body)")   \
  FIELD(double, max_range_m, 200.0, range::positive_up_to_or_inf(kMaxDistance_m), \
        "points farther than this are dropped")                                   \
  FIELD(bool, undistort, true, range::unchecked(), "motion undistortion (MU) of points with per-point times")

// ---- map: the voxel hash map (the paper's cuVoxelMap), the adaptive local submap ----------------
#define FARLIO_MAP_FIELDS(FIELD)                                                                              \
  FIELD(double, voxel_size_m, 4.0, range::between(kMinVoxelSize_m, kMaxVoxelSize_m),                          \
        "v: edge of a voxel cube (paper: 4 m); the upper bound when auto_voxel_size")                         \
  FIELD(bool, auto_voxel_size, true, range::unchecked(),                                                      \
        "scale the voxel to the scene at the first scan: v = clamp(p90 range / auto_range_ratio, "            \
        "auto_min_voxel_size_m, voxel_size_m), then smaller until the scan fills auto_min_voxels voxels; "    \
        "vehicles outdoors keep 4 m, rooms and narrow fields of view get a finer map")                        \
  FIELD(double, auto_range_ratio, 6.0, range::positive_up_to(kMaxRatio),                                      \
        "p90 range of the first scan over the voxel size (auto)")                                             \
  FIELD(double, auto_min_voxel_size_m, 0.5, range::between(kMinVoxelSize_m, kMaxVoxelSize_m),                 \
        "smallest voxel the auto scaling picks")                                                              \
  FIELD(int, auto_min_voxels, 200, range::between(0, kMaxCount),                                              \
        "auto: the voxel shrinks by 10 % steps (down to auto_min_voxel_size_m) until the first scan fills "   \
        "this many voxels: a forward Livox facing a room fills ~90 at the range rule's 1.3 m (0: off)")       \
  FIELD(int, max_points_per_voxel, 40, range::between(1, kMaxPointsPerVoxel),                                 \
        "N_max: points a voxel holds at most (paper: 40)")                                                    \
  FIELD(double, point_spacing_m, 0.0, range::non_negative_up_to(kMaxVoxelSize_m),                             \
        "minimum distance between points of a voxel; 0: voxel_size_m / sqrt(N_max) (0.63 m at 4 m)")          \
  FIELD(int, covariance_neighbors, 10, range::between(1, kMaxCovarianceNeighbors),                            \
        "k nearest neighbours of a point covariance (paper: 10)")                                             \
  FIELD(double, covariance_epsilon, 1e-3, range::positive_up_to(kMaxSiValue),                                 \
        "eps of the Frobenius regularisation: C = Sigma_hat + eps I, eq. (1)")                                \
  FIELD(double, line_eigenvalue_ratio, 10.0, range::non_negative_up_to(kMaxRatio),                            \
        "a covariance is line-like (a scan line, a pole) when, regularised, its middle eigenvalue is "        \
        "below ratio x the smallest while the largest is above it; 0: never (all surfaces)")                  \
  FIELD(double, removal_radius_m, 1000.0, range::positive_up_to_or_inf(kMaxDistance_m),                       \
        "voxels whose centre is farther than this from the pose are removed (inf: never)")                    \
  FIELD(bool, refresh_covariances, true, range::unchecked(),                                                  \
        "recompute the covariances of existing points in voxels that receive new points "                     \
        "(the reference never refreshes them)")                                                               \
  FIELD(double, export_resolution_m, 0.0, range::non_negative_up_to(kMaxVoxelSize_m),                         \
        "cell of the whole map farlio run --save-map writes (one centroid a cell); 0: the point spacing")     \
  FIELD(double, export_tile_m, 64.0, range::between(1.0, kMaxDistance_m),                                     \
        "the whole map keeps in memory the tiles of this edge the sensor can reach; the others wait on disk " \
        "beside the outputs until the end of the run")                                                        \
  FIELD(std::int64_t, initial_voxel_capacity, 1 << 14, range::between(1, kMaxVoxelCapacity),                  \
        "voxels preallocated; the pool doubles as needed")                                                    \
  FIELD(std::int64_t, max_voxel_capacity, 1 << 20, range::between(1, kMaxVoxelCapacity),                      \
        "hard limit of the submap in voxels: growth beyond it is a CapacityError")

// ---- density: adaptive submap density (ASMD), the per-voxel limit follows the scan's density ---
#define FARLIO_DENSITY_FIELDS(FIELD)                                                     \
  FIELD(bool, enabled, true, range::unchecked(), "adaptive submap density (ASMD)")       \
  FIELD(double, close_range_m, 20.0, range::positive_up_to(kMaxDistance_m),              \
        "the scan's density is averaged over frame-map voxels within this range")        \
  FIELD(double, slope_points_per_m, 0.03, range::non_negative_up_to(kMaxPointsPerVoxel), \
        "linear decay of the per-voxel limit beyond close_range_m")                      \
  FIELD(int, frame_map_max_points_per_voxel, 20, range::between(1, kMaxPointsPerVoxel),  \
        "cap of the per-scan frame map that gives the source covariances (reference: 20)")

// ---- threshold: KISS-ICP's adaptive correspondence threshold -----------------------------------
#define FARLIO_THRESHOLD_FIELDS(FIELD)                                        \
  FIELD(double, initial_threshold_m, 1.0, range::positive_up_to(kMaxSiValue), \
        "sigma before any model deviation is observed")                       \
  FIELD(double, min_motion_m, 0.25, range::non_negative_up_to(kMaxSiValue),   \
        "model deviations below this are not sampled")                        \
  FIELD(double, max_range_m, 100.0, range::positive_up_to(kMaxDistance_m),    \
        "range that turns a rotation error into a displacement")              \
  FIELD(double, max_threshold_m, 10.0, range::positive_up_to(kMaxSiValue), "sigma is capped here")

// ---- registration: sparsity-aware GICP, scan to submap -----------------------------------------
#define FARLIO_REGISTRATION_FIELDS(FIELD)                                                                         \
  FIELD(bool, sparsity_aware, true, range::unchecked(),                                                           \
        "GICP (true) or plain point-to-point ICP for every point (false)")                                        \
  FIELD(double, point_to_point_sigma_m, 0.0, range::non_negative_up_to(kMaxSiValue),                              \
        "residual std per axis of points without covariance (point-to-point factors); 0: half the map "           \
        "spacing; the paper's Omega = I is sqrt(map.covariance_epsilon) = 0.0316 (docs/odometry.md)")             \
  FIELD(bool, skip_line_pairs, true, range::unchecked(),                                                          \
        "leave out correspondences whose two covariances are both line-like: two scan lines recorded "            \
        "from the same place fake a constraint across the line")                                                  \
  FIELD(int, max_iterations, 500, range::between(1, kMaxCount), "Gauss-Newton iterations at most")                \
  FIELD(double, convergence_norm, 5e-3, range::positive_up_to(kMaxSiValue),                                       \
        "stop when |dx| (6-vector, m and rad) falls below this")                                                  \
  FIELD(double, correspondence_reuse_m, 0.02, range::non_negative_up_to(kMaxSiValue),                             \
        "a source point keeps its map match over Gauss-Newton iterations until it has moved this far from where " \
        "the match was searched (0: a search every iteration, as the paper; on both backends)")                   \
  FIELD(int, coarse_stride, 4, range::between(1, kMaxCount),                                                      \
        "after a Gauss-Newton step longer than coarse_step_norm (a far guess: the second scan, a restart), the "  \
        "next iterations use every n-th source point until the steps are short again; the last iterations use "   \
        "all (1: never coarse)")                                                                                  \
  FIELD(double, coarse_step_norm, 0.1, range::positive_up_to(kMaxSiValue),                                        \
        "|dx| (6-vector, m and rad) above which the next Gauss-Newton iteration is coarse (coarse_stride)")       \
  FIELD(double, time_budget_factor, 2.0, range::positive_up_to_or_inf(kMaxRatio),                                 \
        "time budget in LiDAR periods (paper: 2); a frame over it is dropped (inf: no budget)")                   \
  FIELD(double, max_wait_periods, 0.5, range::between(0.0, 1.0),                                                  \
        "a scan that arrives while the pipeline is busy waits for it up to this many LiDAR periods (a newer "     \
        "scan arriving meanwhile takes its place); one that would wait longer is dropped: a burst from the "      \
        "transport loses no scan and latency stays bounded; 0: dropped at once (the paper)")                      \
  FIELD(double, fused_kernel_scale_m, 0.25, range::positive_up_to(kMaxSiValue),                                   \
        "LIO: the Cauchy kernel scale is at most this when the initial guess is the fusion's prediction. "        \
        "KISS-ICP's sigma / 3 measures a constant-velocity guess; the IMU's guess deviates less than "            \
        "threshold.min_motion_m, so sigma keeps its initial value and sigma / 3 lets wrong matches pull "         \
        "(docs/fusion.md); LiDAR-only keeps sigma / 3, which its standing start needs")                           \
  FIELD(double, confirmed_kernel_scale_m, 0.15, range::positive_up_to(kMaxSiValue),                               \
        "LIO: the kernel scale cap once the fusion's guess is confirmed (the gyro's unit decided against the "    \
        "LiDAR's rotations); tighter than fused_kernel_scale_m, which a guess not yet confirmed (a stuck gyro) "  \
        "needs so that the scans can still show the turn the gyro misses")                                        \
  FIELD(double, damping, 1e-9, range::non_negative_up_to(kMaxRatio), "lambda added to the diagonal of H")         \
  FIELD(double, covariance_scale, 0.05, range::positive_up_to(kMaxRatio),                                         \
        "pose covariance = covariance_scale * H^-1 (H in the factors' normalised units; docs/fusion.md measures " \
        "1e-3..2e-3 on consecutive scans and inflates it for errors shared through the map)")                     \
  FIELD(double, degenerate_translation_std_m, 0.05, range::positive_up_to(kMaxSiValue),                           \
        "a body-frame direction whose translation std (from covariance_scale * H^-1) exceeds this, and its "      \
        "std per point degenerate_translation_point_std_m, is degenerate")                                        \
  FIELD(double, degenerate_translation_point_std_m, 2.5, range::non_negative_up_to(kMaxSiValue),                  \
        "a direction over degenerate_translation_std_m is degenerate only if its std times sqrt(inliers) also "   \
        "exceeds this (the std per matched point: how loosely the "                                               \
        "scene's geometry holds the direction, whatever the number of points; 0: the std alone decides)")         \
  FIELD(double, degenerate_rotation_std_rad, 0.01, range::positive_up_to(kMaxSiValue),                            \
        "a body-frame axis whose rotation std exceeds this is degenerate")                                        \
  FIELD(bool, hold_degenerate_directions, true, range::unchecked(),                                               \
        "LIO: Gauss-Newton does not move the pose along degenerate directions (they stay at the IMU prediction) " \
        "and the fusion takes them from the IMU; false, or LiDAR-only: the scan's weak constraint is used")       \
  FIELD(int, min_inliers, 100, range::between(1, kMaxCount),                                                      \
        "a registration with fewer correspondences has failed: the scan keeps the predicted pose and updates "    \
        "neither the map, the adaptive threshold nor the fusion")                                                 \
  FIELD(double, min_inlier_fraction, 0.5, range::fraction(),                                                      \
        "a registration matching fewer of the source points has failed (a scan of something else: a bogus "       \
        "scan, a sensor fault), unless it stayed within the kernel scale of the fusion's guess (new space)")      \
  FIELD(double, map_restart_after_s, 1.0, range::positive_up_to_or_inf(kMaxSiValue),                              \
        "after failed registrations for this long, the map restarts from the current scan at the prediction")

// ---- fusion: the kinematic EKF (paper eqs. 7-10) fusing IMU inputs with LiDAR poses -------------
// Variances are given as standard deviations (unit in the name); docs/fusion.md explains each. The
// filter's own fields are listed here, its parts in the sub-sections below (fusion.init, fusion.bias,
// fusion.imu_gate, fusion.reference_angles, fusion.delay, fusion.standstill, fusion.units).
#define FARLIO_FUSION_FIELDS(FIELD)                                                                                   \
  FIELD(bool, enabled, true, range::unchecked(), "fuse the IMU (LIO); false or no IMU: LiDAR-only odometry")          \
  FIELD(double, step_s, 0.01, range::between(1e-4, 1.0), "fixed EKF step and odometry output period (paper: 100 Hz)") \
  FIELD(double, history_s, 1.0, range::positive_up_to(kMaxDuration_s),                                                \
        "state history kept for delay compensation and pose queries")                                                 \
  FIELD(double, max_extrapolation_s, 0.1, range::non_negative_up_to(kMaxDuration_s),                                  \
        "a pose may be predicted this far beyond the newest step")                                                    \
  FIELD(double, gyro_input_std_rad_s, 0.02, range::positive_up_to(kMaxSiValue),                                       \
        "std of the gyro input averaged over one step, process noise B Q B^T (reference: variances "                  \
        "3e-4..3e-3 rad^2/s^2 at 100 Hz); the least used: a gyro measured noisier on its samples gets its own")       \
  FIELD(double, accel_input_std_m_s2, 1.0, range::positive_up_to(kMaxSiValue),                                        \
        "std of the accelerometer input averaged over one step, process noise B Q B^T (reference: variances "         \
        "1..4 m^2/s^4 at 100 Hz); the least used: an accelerometer measured noisier on its samples gets its own")     \
  FIELD(double, lidar_position_std_m, 0.05, range::positive_up_to(kMaxSiValue),                                       \
        "LiDAR position measurement std per axis")                                                                    \
  FIELD(double, lidar_roll_pitch_std_rad, 0.02, range::positive_up_to(kMaxSiValue),                                   \
        "LiDAR roll and pitch measurement std")                                                                       \
  FIELD(double, lidar_yaw_std_rad, 0.01, range::positive_up_to(kMaxSiValue), "LiDAR yaw measurement std")             \
  FIELD(double, lidar_velocity_std_m_s, 0.8, range::positive_up_to(kMaxSiValue),                                      \
        "LiDAR body velocity (eq. 6) measurement std per axis, and the velocity's std at initialisation")             \
  FIELD(bool, lidar_information_from_registration, true, range::unchecked(),                                          \
        "the LiDAR pose is fused with its registration's covariance (registration.covariance_scale * H^-1, "          \
        "tight where the scene constrains it, loose where degenerate) instead of the fixed lidar_*_std")              \
  FIELD(double, lidar_min_position_std_m, 0.002, range::positive_up_to(kMaxSiValue),                                  \
        "floor of the registration's position std per axis")                                                          \
  FIELD(double, lidar_min_attitude_std_rad, 2e-4, range::positive_up_to(kMaxSiValue),                                 \
        "floor of the registration's attitude std")                                                                   \
  FIELD(bool, outlier_rejection, true, range::unchecked(), "Mahalanobis outlier rejection per measurement group")     \
  FIELD(double, outlier_chi2_3dof, 16.27, range::positive_up_to(kMaxRatio),                                           \
        "chi-square gate of 3-dof groups (99.9 % quantile)")                                                          \
  FIELD(double, outlier_chi2_2dof, 13.82, range::positive_up_to(kMaxRatio),                                           \
        "chi-square gate of 2-dof groups (99.9 % quantile)")                                                          \
  FIELD(double, outlier_chi2_6dof, 22.46, range::positive_up_to(kMaxRatio),                                           \
        "chi-square gate of 6-dof groups (99.9 % quantile)")                                                          \
  FIELD(int, max_consecutive_rejections, 10, range::between(1, kMaxCount),                                            \
        "LiDAR positions rejected in a row before the filter re-initialises from the LiDAR pose")

// ---- fusion.init: the filter's start (fusion/initialization.hpp) --------------------------------
#define FARLIO_FUSION_INIT_FIELDS(FIELD)                                                                              \
  FIELD(double, position_std_m, 0.1, range::positive_up_to(kMaxSiValue),                                              \
        "position std at initialisation (the first LiDAR pose)")                                                      \
  FIELD(double, attitude_std_rad, 0.02, range::positive_up_to(kMaxSiValue), "roll/pitch/yaw std at initialisation")   \
  FIELD(double, window_s, 0.7, range::positive_up_to(kMaxDuration_s),                                                 \
        "the filter starts from the LiDAR results of its first scans and the IMU between them: at rest from two, in " \
        "motion from those of this span (gravity in the map frame and the velocity, fusion/initialization.hpp)")

// ---- fusion.bias: the IMU biases (filter states and the fixed initial values) -------------------
#define FARLIO_FUSION_BIAS_FIELDS(FIELD)                                                                        \
  FIELD(bool, estimate, true, range::unchecked(),                                                               \
        "gyro and accelerometer biases as filter states (false: the paper's 9-state filter)")                   \
  FIELD(double, gyro_std_rad_s, 0.01, range::positive_up_to(kMaxSiValue), "initial std of the gyro bias state") \
  FIELD(double, accel_std_m_s2, 0.1, range::positive_up_to(kMaxSiValue),                                        \
        "initial std of the accelerometer bias state")                                                          \
  FIELD(double, gyro_walk_rad_s2_sqrt_hz, 2e-4, range::non_negative_up_to(kMaxSiValue),                         \
        "gyro bias random walk density")                                                                        \
  FIELD(double, accel_walk_m_s3_sqrt_hz, 2e-3, range::non_negative_up_to(kMaxSiValue),                          \
        "accelerometer bias random walk density")                                                               \
  FIELD(double, gyro_init_x_rad_s, 0.0, range::symmetric(kMaxGyroBias_rad_s), "initial gyro bias x")            \
  FIELD(double, gyro_init_y_rad_s, 0.0, range::symmetric(kMaxGyroBias_rad_s), "initial gyro bias y")            \
  FIELD(double, gyro_init_z_rad_s, 0.0, range::symmetric(kMaxGyroBias_rad_s), "initial gyro bias z")            \
  FIELD(double, accel_init_x_m_s2, 0.0, range::symmetric(kMaxAccelBias_m_s2),                                   \
        "accelerometer bias x subtracted from every sample (fixed, as in the paper; with "                      \
        "fusion.bias.estimate the filter's bias state adds to it)")                                             \
  FIELD(double, accel_init_y_m_s2, 0.0, range::symmetric(kMaxAccelBias_m_s2),                                   \
        "accelerometer bias y subtracted from every sample (fixed, as in the paper; with "                      \
        "fusion.bias.estimate the filter's bias state adds to it)")                                             \
  FIELD(double, accel_init_z_m_s2, 0.0, range::symmetric(kMaxAccelBias_m_s2),                                   \
        "accelerometer bias z subtracted from every sample (fixed, as in the paper; with "                      \
        "fusion.bias.estimate the filter's bias state adds to it)")

// ---- fusion.imu_gate: IMU clock gaps and implausible samples (fusion/imu_gate.hpp) -------------
#define FARLIO_FUSION_IMU_GATE_FIELDS(FIELD)                                                                         \
  FIELD(double, gap_limit_s, 0.1, range::positive_up_to(kMaxDuration_s),                                             \
        "IMU samples farther apart are a gap: the last input is held")                                               \
  FIELD(double, max_bridged_gap_s, 1.0, range::positive_up_to(kMaxDuration_s),                                       \
        "largest jump of the IMU clock the fusion takes: a gap up to this is predicted across, a sample up to this " \
        "older than the newest is dropped; a larger jump either way resets the fusion with a warning (it starts "    \
        "again from the next LiDAR result), and a LiDAR result older than the IMU clock by more does not "           \
        "initialise the filter")                                                                                     \
  FIELD(double, max_accel_m_s2, 160.0, range::positive_up_to(kMaxSiValue),                                           \
        "an IMU sample with |accel| over this is impossible and rejected (16 g: MEMS full scale)")                   \
  FIELD(double, max_gyro_rad_s, 35.0, range::positive_up_to(kMaxSiValue),                                            \
        "an IMU sample with |gyro| over this is impossible and rejected (2000 deg/s: MEMS full scale)")              \
  FIELD(double, spike_accel_m_s2, 50.0, range::positive_up_to(kMaxSiValue),                                          \
        "an accelerometer axis this far from the median of the recent samples is a spike: rejected")                 \
  FIELD(double, spike_gyro_rad_s, 10.0, range::positive_up_to(kMaxSiValue),                                          \
        "a gyro axis this far from the median of the recent samples is a spike: rejected")                           \
  FIELD(int, spike_window_samples, 9, range::between(0, kMaxCount),                                                  \
        "samples in the spike median (0: no spike test); a real step passes after half of them")

// ---- fusion.reference_angles: roll/pitch from gravity, a pseudo-measurement ---------------------
#define FARLIO_FUSION_REFERENCE_ANGLES_FIELDS(FIELD)                                             \
  FIELD(bool, enabled, true, range::unchecked(),                                                 \
        "fuse roll/pitch reference angles, a pseudo-measurement from gravity in the body frame") \
  FIELD(double, roll_std_rad, 0.22, range::positive_up_to(kMaxSiValue),                          \
        "reference roll std (reference: variance 0.05 rad^2)")                                   \
  FIELD(double, pitch_std_rad, 0.32, range::positive_up_to(kMaxSiValue),                         \
        "reference pitch std (reference: variance 0.1 rad^2)")                                   \
  FIELD(int, filter_taps, 11, range::between(1, kMaxCount),                                      \
        "taps of the Hann low-pass of the reference angle terms (odd)")                          \
  FIELD(double, max_sin, 0.5, range::fraction(),                                                 \
        "clamp of the asin argument (30 deg); clamped reference angles are not fused")

// ---- fusion.delay: delayed LiDAR results (eq. 10) -----------------------------------------------
#define FARLIO_FUSION_DELAY_FIELDS(FIELD)                                                         \
  FIELD(bool, compensation, true, range::unchecked(), "shift delayed measurements by eq. (10)")   \
  FIELD(int, spread_steps, 0, range::non_negative_up_to(kMaxCount),                               \
        "N: a LiDAR result is injected over N steps with N R each; 0: the LiDAR period / step_s") \
  FIELD(int, max_spread_steps, 20, range::between(1, kMaxCount), "cap of the automatic N")

// ---- fusion.standstill: the gyro bias learnt at standstill (fusion/standstill_bias.hpp) ---------
#define FARLIO_FUSION_STANDSTILL_FIELDS(FIELD)                                                                    \
  FIELD(bool, gyro_bias, true, range::unchecked(),                                                                \
        "learn the gyro bias at standstill (the accelerometer bias stays at its initial value, as in the paper)") \
  FIELD(double, max_speed_m_s, 0.1, range::non_negative_up_to(kMaxSiValue),                                       \
        "standstill: estimated speed below this (a walk's first steps are slower than 0.4 m/s)")                  \
  FIELD(double, max_gyro_rad_s, 0.05, range::non_negative_up_to(kMaxSiValue), "standstill: |gyro| below this")    \
  FIELD(double, max_accel_deviation_m_s2, 1.0, range::non_negative_up_to(kMaxSiValue),                            \
        "standstill: | |accel| - g | below this")                                                                 \
  FIELD(int, window_samples, 10000, range::between(1, kMaxCount),                                                 \
        "gyro bias running mean over at most this many samples")                                                  \
  FIELD(int, prior_samples, 100, range::non_negative_up_to(kMaxCount),                                            \
        "weight of the initial gyro bias in the mean, in samples")

// ---- fusion.units: IMUs reporting in g or deg/s -------------------------------------------------
#define FARLIO_FUSION_UNITS_FIELDS(FIELD)                                                                           \
  FIELD(bool, accel_detection, true, range::unchecked(), "detect an accelerometer reporting in g and scale it")     \
  FIELD(int, accel_samples, 50, range::between(1, kMaxCount),                                                       \
        "the mean |accel| of these first samples decides the unit")                                                 \
  FIELD(bool, gyro_detection, true, range::unchecked(),                                                             \
        "detect a gyro reporting in deg/s (its rotation ~57x the LiDAR's) and scale it; a gyro that stays "         \
        "constant while the LiDAR turns is not used")                                                               \
  FIELD(double, gyro_min_rotation_rad, 0.1, range::positive_up_to(kMaxSiValue),                                     \
        "the gyro unit is decided once the gyro's or the LiDAR's rotation over the scans reaches this; until then " \
        "a scan during which the gyro turns is registered without the fusion's guess")

// ---- cuda: the CUDA backend's device buffers, allocated once when the pipeline starts ----------
// A scan or map beyond them raises CapacityError naming the field to raise (docs/cuda.md).
#define FARLIO_CUDA_FIELDS(FIELD)                                                      \
  FIELD(std::int64_t, max_scan_points, 1 << 19, range::between(1, kMaxVoxelCapacity),  \
        "device buffers: points of one scan, all LiDARs merged (racetrack: ~210k)")    \
  FIELD(std::int64_t, max_map_voxels, 1 << 18, range::between(1, kMaxVoxelCapacity),   \
        "device buffers: submap voxels (N_max points each)")                           \
  FIELD(std::int64_t, max_frame_voxels, 1 << 16, range::between(1, kMaxVoxelCapacity), \
        "device buffers: voxels of the per-scan frame map")

// ---- top level ---------------------------------------------------------------------------------
// ---- localization: odometry in a prior map held fixed (farlio run --prior-map) -------------------
#define FARLIO_LOCALIZATION_FIELDS(FIELD)                                                                      \
  FIELD(double, min_inlier_fraction, 0.9, range::fraction(),                                                   \
        "a scan registered in the prior map that matches fewer of its source points is lost (timing.csv) and " \
        "its pose not used: a scan of the mapped scene matches 0.97-0.99, the ground alone 30 m off 0.8")

// ---- loop: loop closure over a whole run (farlio run --loop-closure; docs/maps.md) ------------
#define FARLIO_LOOP_FIELDS(FIELD)                                                                                   \
  FIELD(double, keyframe_distance_m, 10.0, range::positive_up_to(kMaxDistance_m),                                   \
        "a keyframe (a pose-graph node) starts after this much travel; its scans until the next form its segment")  \
  FIELD(double, submap_length_m, 40.0, range::positive_up_to(kMaxDistance_m),                                       \
        "a keyframe's submap: its segment and those of this much path before it (what a loop registers)")           \
  FIELD(double, search_radius_m, 15.0, range::positive_up_to(kMaxDistance_m),                                       \
        "candidates lie within this distance of the query (global estimate), plus 0.5 % of the path between them")  \
  FIELD(double, min_overlap, 0.7, range::fraction(),                                                                \
        "a loop is refused unless this fraction of the query submap's cells land on the candidate's map (revisits " \
        "of a road overlap 0.72-0.98; loops 0.4-1.4 m off overlapped 0.52-0.59)")                                   \
  FIELD(double, max_ambiguity_m, 0.3, range::positive_up_to(kMaxDistance_m),                                        \
        "a loop is refused when registrations started 4 m and 10 deg around it end farther apart (repeated "        \
        "structure: evenly spaced posts, identical corridors)")

#define FARLIO_TOP_FIELDS(FIELD)                                                           \
  FIELD(Device, device, Device::Auto, range::unchecked(),                                  \
        "scan pipeline backend: auto (CUDA when a GPU is present, else CPU), cpu or cuda") \
  FIELD(int, num_threads, 0, range::non_negative_up_to(kMaxThreads), "CPU threads of this pipeline instance (0: all)")

#define FARLIO_CONFIG_MEMBER(type, name, default_value, valid, doc) type name = default_value;

struct PreprocessConfig {
  FARLIO_PREPROCESS_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct VoxelMapConfig {
  FARLIO_MAP_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct AdaptiveDensityConfig {
  FARLIO_DENSITY_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct ThresholdConfig {
  FARLIO_THRESHOLD_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct RegistrationConfig {
  FARLIO_REGISTRATION_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionInitConfig {
  FARLIO_FUSION_INIT_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionBiasConfig {
  FARLIO_FUSION_BIAS_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionImuGateConfig {
  FARLIO_FUSION_IMU_GATE_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionReferenceAnglesConfig {
  FARLIO_FUSION_REFERENCE_ANGLES_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionDelayConfig {
  FARLIO_FUSION_DELAY_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionStandstillConfig {
  FARLIO_FUSION_STANDSTILL_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct FusionUnitsConfig {
  FARLIO_FUSION_UNITS_FIELDS(FARLIO_CONFIG_MEMBER)
};
/// The filter's own fields, then its parts: dotted names fusion.<field> and fusion.<part>.<field>.
struct FusionConfig {
  FARLIO_FUSION_FIELDS(FARLIO_CONFIG_MEMBER)
  FusionInitConfig init;
  FusionBiasConfig bias;
  FusionImuGateConfig imu_gate;
  FusionReferenceAnglesConfig reference_angles;
  FusionDelayConfig delay;
  FusionStandstillConfig standstill;
  FusionUnitsConfig units;
};
struct LocalizationConfig {
  FARLIO_LOCALIZATION_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct LoopClosureConfig {
  FARLIO_LOOP_FIELDS(FARLIO_CONFIG_MEMBER)
};
struct CudaConfig {
  FARLIO_CUDA_FIELDS(FARLIO_CONFIG_MEMBER)
};

struct Config {
  PreprocessConfig preprocess;
  VoxelMapConfig map;
  AdaptiveDensityConfig density;
  ThresholdConfig threshold;
  RegistrationConfig registration;
  FusionConfig fusion;
  LocalizationConfig localization;
  LoopClosureConfig loop;
  CudaConfig cuda;
  FARLIO_TOP_FIELDS(FARLIO_CONFIG_MEMBER)
};

#undef FARLIO_CONFIG_MEMBER

}  // namespace farlio
