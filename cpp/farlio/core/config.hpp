#pragma once
// The one parameter set of farlio. Every field has its unit in its name and a documented
// default; the defaults serve every sensor and dataset (one parameter set, as in the paper).
// YAML files and command-line overrides map onto these fields by their dotted names
// (e.g. `map.voxel_size_m`); a run writes the full effective config next to its outputs.
#include <cstdint>

#include "farlio/core/device.hpp"

namespace farlio {

/// Range crop and downsampling of each incoming scan.
struct PreprocessConfig {
  double min_range_m = 1.0;     ///< points closer than this to the sensor are dropped (vehicle body)
  double max_range_m = 200.0;   ///< points farther than this are dropped
  bool undistort = true;        ///< motion undistortion (MU) of points with per-point times
};

/// The voxel hash map (cuVoxelMap): the adaptive local submap and the per-scan frame map.
struct VoxelMapConfig {
  double voxel_size_m = 4.0;           ///< v: edge of a voxel cube (paper: 4 m); the upper bound when auto
  /// Scale the voxel to the scene at the first scan: v = clamp(p90 range / auto_range_ratio,
  /// auto_min_voxel_size_m, voxel_size_m). Vehicles outdoors keep the paper's 4 m; rooms and
  /// corridors get a finer map (a 4 m voxel spans a whole room).
  bool auto_voxel_size = true;
  double auto_range_ratio = 6.0;
  double auto_min_voxel_size_m = 1.0;
  int max_points_per_voxel = 40;       ///< N_max (paper: 40)
  /// Minimum distance between points of a voxel; 0: sqrt(v^2 / N_max) (~0.63 m by default).
  double point_spacing_m = 0.0;
  int covariance_neighbors = 10;       ///< k nearest neighbours for a point covariance (paper: 10)
  double covariance_epsilon = 1e-3;    ///< C = Sigma_hat + eps * I before Frobenius normalisation (eq. 1)
  /// A covariance is line-like when, after regularisation, its middle eigenvalue is below this
  /// ratio times the smallest while the largest is above it (points along one scan line or a
  /// pole). 0: never classify (every covariance counts as a surface).
  double line_eigenvalue_ratio = 10.0;
  double removal_radius_m = 1000.0;    ///< voxels whose centre is farther from the pose are removed
  /// Recompute the covariances of existing points in voxels that received new points (the
  /// reference never refreshes them).
  bool refresh_covariances = true;
  std::int64_t initial_voxel_capacity = 1 << 14;  ///< voxels preallocated; doubles as needed
  std::int64_t max_voxel_capacity = 1 << 20;      ///< growth beyond this raises CapacityError
};

/// Adaptive submap density (ASMD): the per-voxel point limit follows the scan's density.
struct AdaptiveDensityConfig {
  bool enabled = true;
  double close_range_m = 20.0;          ///< density is averaged over frame-map voxels within this range
  double slope_points_per_m = 0.03;     ///< linear decay of the limit beyond close_range_m
  int frame_map_max_points_per_voxel = 20;  ///< cap of the per-scan frame map (reference: 20)
};

/// KISS-ICP-style adaptive correspondence threshold.
struct ThresholdConfig {
  double initial_threshold_m = 1.0;     ///< sigma before any model deviation is observed
  double min_motion_m = 0.25;           ///< deviations below this are not sampled
  double max_range_m = 100.0;           ///< turns a rotation error into a translation error
  double max_threshold_m = 10.0;        ///< sigma is capped here
};

/// Sparsity-aware GICP (scan to submap).
struct RegistrationConfig {
  bool sparsity_aware = true;           ///< GICP (true) or plain point-to-point ICP for every point (false)
  /// Points without a covariance (too few neighbours) enter as point-to-point factors whose
  /// residual has this standard deviation per axis; 0: half the map's point spacing (the matched
  /// sample may lie that far away: 32 cm at 4 m voxels). The paper weights them like a
  /// surface's normal (Omega = I, i.e. sqrt(map.covariance_epsilon) = 3.2 cm), which lets a few far
  /// points matched to their own earlier samples pin a scan to a standstill (docs/odometry.md).
  double point_to_point_sigma_m = 0.0;
  /// Leave out correspondences whose two covariances are both line-like (map.line_eigenvalue_ratio):
  /// two scan lines recorded from the same place fake a constraint across the line.
  bool skip_line_pairs = true;
  int max_iterations = 500;
  double convergence_norm = 5e-3;       ///< stop when |dx| (6-vector, m and rad) falls below this
  double time_budget_factor = 2.0;      ///< time budget = factor * LiDAR period (paper: 2)
  double damping = 1e-9;                ///< lambda added to the diagonal of H
};

/// Sensor fusion: the kinematic EKF (paper eqs. 7-10) that fuses IMU inputs with LiDAR poses.
/// Variances are given as standard deviations (unit in the name); docs/fusion.md explains each.
struct FusionConfig {
  bool enabled = true;                   ///< fuse the IMU (LIO); false or no IMU: LiDAR-only odometry
  double step_s = 0.01;                  ///< fixed EKF step (paper: 100 Hz)
  double history_s = 1.0;                ///< state history for delay compensation and pose queries
  double max_extrapolation_s = 0.1;      ///< pose_at() may predict this far beyond the newest step
  double imu_gap_limit_s = 0.1;          ///< IMU samples farther apart are a gap: the last input is held
  // Input noise: std of the IMU input averaged over one step, mapped into the state as B Q B^T
  // (reference: variances 3e-4..3e-3 rad^2/s^2 and 1.0..4.0 m^2/s^4 at 100 Hz).
  double gyro_input_std_rad_s = 0.02;
  double accel_input_std_m_s2 = 1.0;
  // Initial covariance (the first LiDAR pose initialises the state).
  double initial_position_std_m = 0.1;
  double initial_attitude_std_rad = 0.02;
  double initial_velocity_std_m_s = 20.0;  ///< used when the first LiDAR result carries no velocity
  // LiDAR measurement noise (std per axis).
  double lidar_position_std_m = 0.05;
  double lidar_roll_pitch_std_rad = 0.02;
  double lidar_yaw_std_rad = 0.01;
  double lidar_velocity_std_m_s = 0.8;
  // Mahalanobis outlier rejection per measurement group.
  bool outlier_rejection = true;
  double outlier_chi2_3dof = 16.27;      ///< chi-square 99.9 % quantile, 3 degrees of freedom
  double outlier_chi2_2dof = 13.82;      ///< chi-square 99.9 % quantile, 2 degrees of freedom
  int max_consecutive_rejections = 10;   ///< then the filter re-initialises from the LiDAR pose
  // Roll/pitch reference angles (pseudo-measurement from gravity in the body frame).
  bool reference_angles = true;
  double reference_roll_std_rad = 0.22;  ///< reference: variance 0.05 rad^2
  double reference_pitch_std_rad = 0.32; ///< reference: variance 0.1 rad^2
  int reference_filter_taps = 11;        ///< Hann low-pass on v_dot and the IMU terms (odd)
  double reference_max_sin = 0.5;        ///< asin argument clamp (30 deg); clamped values are not fused
  // Delay compensation (eq. 10) and upsampling of LiDAR results.
  bool delay_compensation = true;
  int update_spread_steps = 0;           ///< N injections with N*R each; 0: LiDAR period / step_s
  int max_update_spread_steps = 20;      ///< cap of the automatic N
  // Gyro bias at standstill (the accelerometer bias stays at its initial value, as in the paper).
  bool standstill_bias = true;
  double standstill_max_speed_m_s = 0.4;
  double standstill_max_gyro_rad_s = 0.05;
  double standstill_max_accel_deviation_m_s2 = 1.0;  ///< | |a| - g | below this
  int bias_window_samples = 10000;       ///< running mean over at most this many samples
  int bias_prior_samples = 100;          ///< weight of the initial bias in the mean, in samples
  double gyro_bias_init_x_rad_s = 0.0;
  double gyro_bias_init_y_rad_s = 0.0;
  double gyro_bias_init_z_rad_s = 0.0;
  double accel_bias_x_m_s2 = 0.0;
  double accel_bias_y_m_s2 = 0.0;
  double accel_bias_z_m_s2 = 0.0;
  // Accelerometer unit detection (IMUs reporting in g).
  bool accel_unit_detection = true;
  int accel_unit_detection_samples = 50; ///< mean |a| over these first samples decides the unit
};

/// The CUDA backend's device buffers, all allocated once when the pipeline starts (docs/cuda.md).
/// A scan or map beyond them raises CapacityError naming the field to raise.
struct CudaConfig {
  std::int64_t max_scan_points = 1 << 19;    ///< points of one scan, all LiDARs merged (racetrack: ~210k)
  std::int64_t max_map_voxels = 1 << 18;     ///< submap voxels on the device (N_max points each)
  std::int64_t max_frame_voxels = 1 << 16;   ///< voxels of the per-scan frame map
};

struct Config {
  PreprocessConfig preprocess;
  VoxelMapConfig map;
  AdaptiveDensityConfig density;
  ThresholdConfig threshold;
  RegistrationConfig registration;
  FusionConfig fusion;
  CudaConfig cuda;
  Device device = Device::Auto;         ///< backend of the scan pipeline: auto (CUDA if a GPU is present), cpu, cuda
  int num_threads = 0;                  ///< CPU threads of this pipeline instance (0: all)
};

}  // namespace farlio
