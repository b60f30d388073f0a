#pragma once
// The one parameter set of farlio. Every field has its unit in its name and a documented
// default; the defaults serve every sensor and dataset (one parameter set, as in the paper).
// YAML files and command-line overrides map onto these fields by their dotted names
// (e.g. `map.voxel_size_m`); a run writes the full effective config next to its outputs.
#include <cstdint>

namespace farlio {

/// Range crop and downsampling of each incoming scan.
struct PreprocessConfig {
  double min_range_m = 1.0;     ///< points closer than this to the sensor are dropped (vehicle body)
  double max_range_m = 200.0;   ///< points farther than this are dropped
};

/// The voxel hash map (cuVoxelMap): the adaptive local submap and the per-scan frame map.
struct VoxelMapConfig {
  double voxel_size_m = 4.0;           ///< v: edge of a voxel cube (paper: 4 m)
  int max_points_per_voxel = 40;       ///< N_max (paper: 40); the spacing is sqrt(v^2 / N_max) ~ 0.63 m
  int covariance_neighbors = 10;       ///< k nearest neighbours for a point covariance (paper: 10)
  double covariance_epsilon = 1e-3;    ///< C = Sigma_hat + eps * I before Frobenius normalisation (eq. 1)
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
  bool sparsity_aware = true;           ///< GICP with point-to-point fallback; false: point-to-point only
  int max_iterations = 500;
  double convergence_norm = 5e-3;       ///< stop when |dx| (6-vector, m and rad) falls below this
  double time_budget_factor = 2.0;      ///< time budget = factor * LiDAR period (paper: 2)
  double damping = 1e-9;                ///< lambda added to the diagonal of H
};

struct Config {
  PreprocessConfig preprocess;
  VoxelMapConfig map;
  AdaptiveDensityConfig density;
  ThresholdConfig threshold;
  RegistrationConfig registration;
  int num_threads = 0;                  ///< CPU threads of this pipeline instance (0: all)
};

}  // namespace farlio
