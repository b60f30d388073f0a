#pragma once
// Adaptive submap density (ASMD, paper III-A): the submap keeps about as many points per voxel as
// the scan itself has close by, so that a dense scan is matched against a dense map and a sparse
// one against a sparse map. The limit is the frame map's mean points per voxel within
// density.close_range_m, clamped to [map.covariance_neighbors, map.max_points_per_voxel], and
// decays by density.slope_points_per_m per metre beyond that range, floored at the neighbours k
// a covariance needs (PointLimit::at, evaluated per inserted point on the CPU and the GPU).
#include "farlio/core/config.hpp"
#include "farlio/map/point_limit.hpp"

namespace farlio::map {

/// The per-voxel limit for a scan whose frame map holds mean_points_per_voxel points per voxel
/// within density.close_range_m; the constant map.max_points_per_voxel when ASMD is off or the
/// density was not measured (0).
PointLimit adaptive_point_limit(double mean_points_per_voxel, const AdaptiveDensityConfig& density,
                                const VoxelMapConfig& map);

}  // namespace farlio::map
