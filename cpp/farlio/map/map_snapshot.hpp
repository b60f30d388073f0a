#pragma once
// A host copy of a voxel map's pool (the layout of map_view.hpp): what a backend hands out for
// export, inspection and the CPU/GPU comparison tests. Voxels are in pool order; a free voxel
// has the key kEmptyKey and no points.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "farlio/map/covariance.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::map {

struct MapSnapshot {
  int max_points_per_voxel = 0;
  std::vector<std::uint64_t> voxel_keys;
  std::vector<std::int32_t> voxel_counts;
  std::vector<Eigen::Vector4f> points;  ///< voxel v's j-th point at v * max_points_per_voxel + j
  std::vector<Cov3> covs;

  /// Calls f(point, covariance, has_covariance) for every stored point, in pool order.
  template <typename F>
  void for_each_point(const F& f) const {
    const auto n = static_cast<std::size_t>(max_points_per_voxel);
    for (std::size_t v = 0; v < voxel_keys.size(); ++v) {
      for (std::size_t j = 0; j < static_cast<std::size_t>(voxel_counts[v]); ++j) {
        const Eigen::Vector4f& p = points[v * n + j];
        f(Eigen::Vector3f(p.head<3>()), covs[v * n + j], has_covariance(p));
      }
    }
  }
};

}  // namespace farlio::map
