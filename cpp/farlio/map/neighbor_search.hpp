#pragma once
// Nearest-neighbour and k-nearest-neighbour search over the 27 voxels around a query point.
// Exact within that neighbourhood: a voxel is skipped only when its box is farther than the
// current best (or k-th best) distance, so the result equals a brute-force search over the
// same 27 voxels. Shared by CPU and CUDA.
#include <Eigen/Core>
#include <cstdint>

#include "farlio/exec/hd.hpp"
#include "farlio/map/map_view.hpp"

namespace farlio::map {

/// Largest k supported by knn_search (fixed-size per-thread storage).
inline constexpr int kMaxNeighbors = 32;

/// Squared distance from p to the box of voxel c (0 inside).
FARLIO_HD inline float voxel_box_distance2(const Eigen::Vector3f& p, const VoxelCoord& c, float voxel_size) {
  float d2 = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const float lo = static_cast<float>(c[a]) * voxel_size;
    const float hi = lo + voxel_size;
    const float d = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0f);
    d2 += d * d;
  }
  return d2;
}

/// Calls visit(voxel_index) for each of the 27 voxels around p (centre first) that exists and
/// whose box is closer than bound2() (re-read before each voxel, so it may shrink).
template <typename Visit, typename Bound>
FARLIO_HD void for_each_nearby_voxel(const ConstMapView& m, const Eigen::Vector3f& p, const Bound& bound2,
                                     const Visit& visit) {
  const VoxelCoord c0 = voxel_of(p, m.inv_voxel_size);
  for (int n = 0; n < 27; ++n) {
    // n = 0 is the centre voxel; the rest in a fixed order.
    const int code = n == 0 ? 13 : (n <= 13 ? n - 1 : n);
    const VoxelCoord c(c0.x() + code % 3 - 1, c0.y() + (code / 3) % 3 - 1, c0.z() + code / 9 - 1);
    if (n > 0 && voxel_box_distance2(p, c, m.voxel_size) >= bound2()) continue;
    const std::int32_t v = table_find(m, c);
    if (v >= 0) visit(v);
  }
}

/// Index (into m.points) of the point nearest to p within sqrt(max_distance2), or -1.
FARLIO_HD inline std::int64_t nearest_neighbor(const ConstMapView& m, const Eigen::Vector3f& p, float max_distance2,
                                               float* distance2 = nullptr) {
  float best = max_distance2;
  std::int64_t best_index = -1;
  for_each_nearby_voxel(
      m, p, [&] { return best; },
      [&](std::int32_t v) {
        const std::int32_t n = m.voxel_counts[v];
        for (std::int32_t j = 0; j < n; ++j) {
          const std::int64_t idx = m.point_index(v, j);
          const float d2 = (m.points[idx].head<3>() - p).squaredNorm();
          if (d2 < best) {
            best = d2;
            best_index = idx;
          }
        }
      });
  if (distance2) *distance2 = best;
  return best_index;
}

/// The k nearest points to p (k <= kMaxNeighbors) within sqrt(max_distance2), sorted by
/// distance. Returns how many were found (< k when the neighbourhood holds fewer).
FARLIO_HD inline int knn_search(const ConstMapView& m, const Eigen::Vector3f& p, int k, float max_distance2,
                                std::int64_t* indices, float* distances2) {
  int found = 0;
  auto bound = [&] { return found < k ? max_distance2 : distances2[k - 1]; };
  for_each_nearby_voxel(m, p, bound, [&](std::int32_t v) {
    const std::int32_t n = m.voxel_counts[v];
    for (std::int32_t j = 0; j < n; ++j) {
      const std::int64_t idx = m.point_index(v, j);
      const float d2 = (m.points[idx].head<3>() - p).squaredNorm();
      if (d2 >= bound()) continue;
      // insertion into the sorted list
      int pos = found < k ? found++ : k - 1;
      while (pos > 0 && distances2[pos - 1] > d2) {
        distances2[pos] = distances2[pos - 1];
        indices[pos] = indices[pos - 1];
        --pos;
      }
      distances2[pos] = d2;
      indices[pos] = idx;
    }
  });
  return found;
}

}  // namespace farlio::map
