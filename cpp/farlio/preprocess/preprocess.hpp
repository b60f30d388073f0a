#pragma once
// Preprocessing of a scan: range crop and voxel-grid downsampling to the map spacing.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/exec/cpu_executor.hpp"

namespace farlio::preprocess {

/// Indices of the points whose range lies in [min_range_m, max_range_m] and that are finite.
std::vector<std::int32_t> crop_by_range(const std::vector<Eigen::Vector3f>& points, const PreprocessConfig& config);

/// Keeps one point per cell of size `cell_m`: the first in the order of `indices` (no
/// centroid, so kept points are measured points). Returns the kept indices, sorted by cell.
std::vector<std::int32_t> voxel_downsample(const std::vector<Eigen::Vector3f>& points,
                                           const std::vector<std::int32_t>& indices, float cell_m,
                                           exec::CpuExecutor& executor);

/// Voxels of size `voxel_m` that `points` fill, counted over at most `max_points` of them (evenly
/// spaced) and no further than `enough` (a scan that fills enough stops the count early: the first
/// scan of a vehicle outdoors fills 200 voxels within its first few hundred points).
std::size_t occupied_voxels(const std::vector<Eigen::Vector3f>& points, double voxel_m, std::size_t max_points,
                            std::size_t enough = std::numeric_limits<std::size_t>::max());

/// The voxel size for a scene whose first scan is `points` (sensor frame): see
/// VoxelMapConfig::auto_voxel_size. Returns config.voxel_size_m when auto is off or the scan
/// is empty.
double scene_voxel_size_m(const std::vector<Eigen::Vector3f>& points, const VoxelMapConfig& config);

}  // namespace farlio::preprocess
