#include "farlio/map/adaptive_density.hpp"

#include <algorithm>

namespace farlio::map {

PointLimit adaptive_point_limit(double mean_points_per_voxel, const AdaptiveDensityConfig& density,
                                const VoxelMapConfig& map) {
  const int n_max = map.max_points_per_voxel, k = map.covariance_neighbors;
  if (!density.enabled || !(mean_points_per_voxel > 0)) return PointLimit::constant(n_max);
  const int close = std::clamp(static_cast<int>(mean_points_per_voxel), k, n_max);
  return {close, static_cast<float>(density.close_range_m), static_cast<float>(density.slope_points_per_m),
          std::min(k, close)};
}

}  // namespace farlio::map
