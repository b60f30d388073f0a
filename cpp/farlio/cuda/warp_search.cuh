#pragma once
// The nearest-neighbour search of one query by a whole warp (nvcc only). Lane n looks up the
// n-th voxel of the 3x3x3 block around the query and scans that voxel's points with the shared
// map::block_distances2; the lanes then agree on the nearest. A frame's GICP system has 10-40k
// queries: at a thread a query, map::nearest_neighbor walks the voxels one after the other and
// leaves the GPU mostly idle (16 frames' queries took 2.2x one frame's time on an H100); a warp
// a query makes it a few dependent memory reads.
//
// The result is map::nearest_neighbor's, ties included. That search keeps the first strictly
// nearer point in its visit order (map::NearOctant::visit_rank), and skips a voxel only when its
// box is no nearer than the best point found before it, which then comes first in that order:
// so it returns the least (distance, visit rank, slot) over the 27 voxels, which the warp takes.
#include <cstdint>

#include "farlio/map/neighbor_search.hpp"

namespace farlio::cuda {

inline constexpr unsigned kWarpLanes = 32;
inline constexpr unsigned kFullWarp = 0xffffffffu;

/// Index (into m.points) of the point nearest to p within sqrt(max_distance2), or -1, as
/// map::nearest_neighbor. Called by all 32 lanes of a warp with the same p; every lane returns it.
__device__ inline std::int64_t warp_nearest_neighbor(const map::ConstMapView& m, const Eigen::Vector3f& p,
                                                     float max_distance2, unsigned lane) {
  constexpr std::uint64_t kNone = ~std::uint64_t{0};
  constexpr int kRankShift = 16;  // a point's slot in its voxel below, the voxel's visit rank above
  std::uint64_t key = kNone;      // (distance bits, visit rank, slot): ordered as the floats are (>= 0)
  std::int64_t index = -1;
  const map::VoxelCoord c0 = map::voxel_of(p, m.inv_voxel_size);
  const map::BlockDistances box(p, c0, m.voxel_size);
  const int n = static_cast<int>(lane);
  if (n < map::kNeighborVoxels && (n == 0 || box.distance2(n) < max_distance2)) {
    const std::int32_t v = map::table_find(m, map::neighbor_voxel(c0, n));
    if (v >= 0) {
      const std::int32_t count = m.voxel_counts[v];
      const std::int64_t first = m.point_index(v, 0);
      float best = max_distance2;
      std::int32_t best_slot = -1;
      for (std::int32_t j0 = 0; j0 < count; j0 += map::kDistanceBlock) {
        float d2[map::kDistanceBlock];
        const std::int32_t len = map::block_distances2(m, first + j0, count - j0, p, d2);
        for (std::int32_t j = 0; j < len; ++j) {
          const bool nearer = d2[j] < best;
          best = nearer ? d2[j] : best;
          best_slot = nearer ? j0 + j : best_slot;
        }
      }
      if (best_slot >= 0) {
        const auto rank = static_cast<std::uint64_t>(map::NearOctant(box).visit_rank(n));
        key = (static_cast<std::uint64_t>(__float_as_uint(best)) << 32) | (rank << kRankShift) |
              static_cast<std::uint64_t>(best_slot);
        index = first + best_slot;
      }
    }
  }
  std::uint64_t least = key;
  for (unsigned offset = kWarpLanes / 2; offset > 0; offset /= 2) {
    const std::uint64_t other = __shfl_xor_sync(kFullWarp, least, offset);
    least = other < least ? other : least;
  }
  if (least == kNone) return -1;
  const int winner = __ffs(__ballot_sync(kFullWarp, key == least)) - 1;  // the keys are distinct
  return __shfl_sync(kFullWarp, index, winner);
}

}  // namespace farlio::cuda
