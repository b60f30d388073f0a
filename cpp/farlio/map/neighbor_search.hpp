#pragma once
// Nearest-neighbour and k-nearest-neighbour search over the 27 voxels around a query point.
// Exact within that neighbourhood: a voxel is skipped only when its box is farther than the
// current best (or k-th best) distance, so the result equals a brute-force search over the
// same 27 voxels. Shared by CPU and CUDA.
#include <Eigen/Core>
#include <cstdint>
#include <limits>

#include "farlio/core/config.hpp"
#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"
#include "farlio/map/map_view.hpp"
#if defined(__SSE2__) && !defined(FARLIO_ON_DEVICE)
#include <emmintrin.h>
#endif

namespace farlio::map {

/// Largest k supported by knn_search (fixed-size per-thread storage).
inline constexpr int kMaxNeighbors = 32;
/// Points of a voxel whose distances the searches compute together (one loop the compiler
/// vectorises, then the comparisons).
inline constexpr int kDistanceBlock = 16;

/// Squared distances from p to the points [first, first + min(remaining, kDistanceBlock)) of the
/// pool, into d2; returns how many.
FARLIO_HD inline std::int32_t block_distances2(const ConstMapView& m, std::int64_t first, std::int32_t remaining,
                                               const Eigen::Vector3f& p, float* d2) {
  const std::int32_t len = remaining < kDistanceBlock ? remaining : kDistanceBlock;
  for (std::int32_t j = 0; j < len; ++j) {
    const Eigen::Vector4f& q = m.points[first + j];
    const float dx = q.x() - p.x(), dy = q.y() - p.y(), dz = q.z() - p.z();
    d2[j] = dx * dx + dy * dy + dz * dz;
  }
  return len;
}

/// Voxels visited around a query: the 27 of the 3x3x3 block, its centre first.
inline constexpr int kNeighborVoxels = 27;

/// The code (x + 3 y + 9 z, offsets + 1) of the centre voxel of the block.
inline constexpr int kCentreCode = 13;

/// The block position of the n-th voxel around a centre (n = 0 is the centre, the rest in a
/// fixed order): axis a is offset by digit a of the code in base 3, minus 1. The searches visit
/// them in a per-query order (for_each_block_neighbor_near_first); all faces, then edges, then
/// corners is not faster (BM_NearestNeighbor, BM_CovarianceKnn).
FARLIO_HD inline int neighbor_code(int n) { return n == 0 ? kCentreCode : (n <= kCentreCode ? n - 1 : n); }

/// The n-th voxel of the block around c0.
FARLIO_HD inline VoxelCoord neighbor_voxel(const VoxelCoord& c0, int n) {
  const int code = neighbor_code(n);
  return {c0.x() + code % 3 - 1, c0.y() + (code / 3) % 3 - 1, c0.z() + code / 9 - 1};
}

/// Squared distance from p to the box of each voxel of the block around c0 (0 inside), from 9
/// distances along the axes computed once per query instead of 3 per voxel.
struct BlockDistances {
  float along[3][3];  ///< [axis][offset + 1]: distance from p to that slab along the axis

  FARLIO_HD BlockDistances(const Eigen::Vector3f& p, const VoxelCoord& c0, float voxel_size) {
    for (int a = 0; a < 3; ++a) {
      for (int o = 0; o < 3; ++o) {
        const float lo = static_cast<float>(c0[a] + o - 1) * voxel_size;
        const float hi = lo + voxel_size;
        along[a][o] = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0f);
      }
    }
  }
  /// Squared distance from p to the nearest face of the centre voxel: no other voxel of the
  /// block is nearer (each is beyond at least one face), so a search whose bound is already this
  /// small has nothing left to visit after the centre.
  [[nodiscard]] FARLIO_HD float nearest_face2() const {
    float d = along[0][0];
    for (int a = 0; a < 3; ++a) {
      d = exec::min_of(d, along[a][0]);
      d = exec::min_of(d, along[a][2]);
    }
    return d * d;
  }
  /// Squared distance from p to the box of the n-th voxel of the block.
  [[nodiscard]] FARLIO_HD float distance2(int n) const {
    const int code = neighbor_code(n);
    const float dx = along[0][code % 3], dy = along[1][(code / 3) % 3], dz = along[2][code / 9];
    float d2 = 0.0f;
    d2 += dx * dx;
    d2 += dy * dy;
    d2 += dz * dz;
    return d2;
  }
};

/// The codes of the 7 voxels of the block around p's octant of the centre voxel, in the order
/// for_each_block_neighbor_near_first visits them.
struct NearOctant {
  int sx, sy, sz;  ///< 0 or 2: the nearer side of the centre voxel on each axis
  int codes[7];

  FARLIO_HD static constexpr int code(int x, int y, int z) { return x + 3 * y + 9 * z; }
  FARLIO_HD explicit NearOctant(const BlockDistances& box)
      : sx(box.along[0][0] < box.along[0][2] ? 0 : 2),
        sy(box.along[1][0] < box.along[1][2] ? 0 : 2),
        sz(box.along[2][0] < box.along[2][2] ? 0 : 2),
        codes{code(sx, 1, 1),  code(1, sy, 1),  code(1, 1, sz),  code(sx, sy, 1),
              code(sx, 1, sz), code(1, sy, sz), code(sx, sy, sz)} {}
  /// The rank of block voxel n in the visit order of a search from p: the centre 0, the octant's
  /// voxels 1 to 7, the others after them in the order of their codes.
  [[nodiscard]] FARLIO_HD int visit_rank(int n) const {
    if (n == 0) return 0;
    const int c = neighbor_code(n);
    for (int k = 0; k < 7; ++k) {
      if (codes[k] == c) return 1 + k;
    }
    return 8 + c;
  }
};

/// Calls f(n) for the voxels n = 1 .. 26 of the block, those of p's octant of the centre voxel
/// first: the 3 face neighbours across its nearer face on each axis, the 3 edge neighbours
/// between them, the corner one; then the 19 others in the order of neighbor_code. A point's
/// nearest neighbours outside its voxel lie mostly in those 7 (the others are at least half a
/// voxel away), so a search's bound tightens before the far voxels, which it then mostly skips:
/// when bound2() is within the nearest far side, none of the 19 is visited. A covariance query
/// of the urban scan compares 40.5 points instead of 45.4 in the order of neighbor_code
/// (bench_kernels' BM_CovarianceKnn counters).
template <typename Bound, typename F>
FARLIO_HD void for_each_block_neighbor_near_first(const BlockDistances& box, const Bound& bound2, const F& f) {
  const auto neighbor = [](int c) { return c < kCentreCode ? c + 1 : c; };  // neighbor_code's inverse
  const NearOctant near(box);
  const int sx = near.sx, sy = near.sy, sz = near.sz;
  std::uint32_t done = 1u << kCentreCode;
  for (const int c : near.codes) {
    done |= 1u << c;
    f(neighbor(c));
  }
  // each of the others lies beyond a far side of the centre voxel
  const float far = exec::min_of(exec::min_of(box.along[0][2 - sx], box.along[1][2 - sy]), box.along[2][2 - sz]);
  if (bound2() <= far * far) return;
  for (int c = 0; c < kNeighborVoxels; ++c) {
    if (((done >> c) & 1u) == 0) f(neighbor(c));
  }
}

/// Calls visit(voxel_index) for each of the 27 voxels around p (centre first, then in
/// for_each_block_neighbor_near_first's order) that exists and whose box is closer than bound2()
/// (re-read before each voxel, so it may shrink). Looks a voxel up only when its box passes the
/// bound.
template <typename Visit, typename Bound>
FARLIO_HD void for_each_nearby_voxel(const ConstMapView& m, const Eigen::Vector3f& p, const Bound& bound2,
                                     const Visit& visit) {
  const VoxelCoord c0 = voxel_of(p, m.inv_voxel_size);
  const BlockDistances box(p, c0, m.voxel_size);
  const std::int32_t centre = table_find(m, c0);
  if (centre >= 0) visit(centre);
  if (bound2() <= box.nearest_face2()) return;  // no other voxel can be nearer
  const auto visit_neighbor = [&](int n) {
    if (box.distance2(n) >= bound2()) return;
    const std::int32_t v = table_find(m, neighbor_voxel(c0, n));
    if (v >= 0) visit(v);
  };
  for_each_block_neighbor_near_first(box, bound2, visit_neighbor);
}

/// The 27 voxels around a voxel, looked up once for all the queries that lie in it (the
/// covariances of a voxel's points): the same voxels, in the same order, as
/// for_each_nearby_voxel visits for any point of the centre voxel.
struct VoxelNeighborhood {
  VoxelCoord centre;
  std::int32_t voxels[kNeighborVoxels];  ///< pool index of each, -1 when absent
};

FARLIO_HD inline VoxelNeighborhood voxel_neighborhood(const ConstMapView& m, const VoxelCoord& centre) {
  VoxelNeighborhood nb;
  nb.centre = centre;
  for (int n = 0; n < kNeighborVoxels; ++n) nb.voxels[n] = table_find(m, neighbor_voxel(centre, n));
  return nb;
}

/// for_each_nearby_voxel over a neighbourhood looked up before (p must lie in its centre voxel).
template <typename Visit, typename Bound>
FARLIO_HD void for_each_nearby_voxel(const ConstMapView& m, const VoxelNeighborhood& nb, const Eigen::Vector3f& p,
                                     const Bound& bound2, const Visit& visit) {
  const BlockDistances box(p, nb.centre, m.voxel_size);
  if (nb.voxels[0] >= 0) visit(nb.voxels[0]);
  if (bound2() <= box.nearest_face2()) return;  // no other voxel can be nearer
  const auto visit_neighbor = [&](int n) {
    if (nb.voxels[n] < 0) return;
    if (box.distance2(n) >= bound2()) return;
    visit(nb.voxels[n]);
  };
  for_each_block_neighbor_near_first(box, bound2, visit_neighbor);
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
        const std::int64_t first = m.point_index(v, 0);
        // the best so far in locals over the voxel (as knn_over's bound): captured by reference
        // they were loaded and stored around every point
        float voxel_best = best;
        std::int32_t voxel_best_slot = -1;
        for (std::int32_t j0 = 0; j0 < n; j0 += kDistanceBlock) {
          float d2[kDistanceBlock];
          const std::int32_t len = block_distances2(m, first + j0, n - j0, p, d2);
          for (std::int32_t j = 0; j < len; ++j) {
            const bool nearer = d2[j] < voxel_best;
            voxel_best = nearer ? d2[j] : voxel_best;
            voxel_best_slot = nearer ? j0 + j : voxel_best_slot;
          }
        }
        if (voxel_best_slot >= 0) {
          best = voxel_best;
          best_index = first + voxel_best_slot;
        }
      });
  if (distance2) *distance2 = best;
  return best_index;
}

/// Bits of a candidate's visit position within its k-NN key: the point's slot in its voxel
/// (below 1024), above it the voxel's rank in the walk (below 27). The block loop over a voxel's
/// points is written out here and in nearest_neighbor: a shared helper taking the per-block
/// lambda makes the covariance stage's k-NN 14 % slower (BM_CovarianceKnn).
inline constexpr int kSlotBits = 10;
static_assert(kMaxPointsPerVoxel < (1 << kSlotBits) && kNeighborVoxels < (1 << (32 - kSlotBits)),
              "a k-NN key's visit position holds a voxel's slot and the voxel's rank in the walk");

/// Points of the first voxel a k-NN visits that the host ranks at once (rank_first_voxel).
inline constexpr int kRankedVoxelPoints = 32;

#if defined(__SSE2__) && !defined(FARLIO_ON_DEVICE)
/// The k-NN list after the first voxel of a walk, on the host: each of its n <= 32 points is
/// ranked by counting the points before it in (distance, slot) order, four comparisons at a
/// time, and the k first go to their places in `best` (the others to best[kMaxNeighbors], a
/// scratch slot). The same list as inserting them one by one, without the insertions' branches,
/// which depend on the distances (most of the k-NN's time: docs/performance.md).
/// Returns how many are in the list.
inline int rank_first_voxel(const ConstMapView& m, std::int64_t first, std::int32_t n, const Eigen::Vector3f& query,
                            int k, float bound, std::uint64_t* best) {
  alignas(16) float d[kRankedVoxelPoints];
  for (std::int32_t j0 = 0; j0 < n; j0 += kDistanceBlock) block_distances2(m, first + j0, n - j0, query, d + j0);
  const int padded = (n + 3) & ~3;
  int valid = 0;
  for (int j = 0; j < padded; ++j) {
    const bool in = j < n && d[j] < bound;  // beyond the bound or padding: after every valid one
    d[j] = in ? d[j] : std::numeric_limits<float>::infinity();
    valid += in ? 1 : 0;
  }
  const int kept = valid < k ? valid : k;
  const __m128i lanes = _mm_set_epi32(3, 2, 1, 0);
  for (int i = 0; i < n; ++i) {
    if (!(d[i] < std::numeric_limits<float>::infinity())) continue;
    const __m128 di = _mm_set1_ps(d[i]);
    const __m128i slot_i = _mm_set1_epi32(i);
    __m128i count = _mm_setzero_si128();
    for (int j = 0; j < padded; j += 4) {
      const __m128 dj = _mm_load_ps(d + j);
      const __m128i earlier = _mm_cmplt_epi32(_mm_add_epi32(_mm_set1_epi32(j), lanes), slot_i);
      const __m128i before = _mm_or_si128(_mm_castps_si128(_mm_cmplt_ps(dj, di)),
                                          _mm_and_si128(_mm_castps_si128(_mm_cmpeq_ps(dj, di)), earlier));
      count = _mm_sub_epi32(count, before);  // a true lane is -1
    }
    alignas(16) std::int32_t c[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(c), count);
    const int place = c[0] + c[1] + c[2] + c[3];
    best[place < kept ? place : kMaxNeighbors] =
        (static_cast<std::uint64_t>(exec::float_bits(d[i])) << 32) | static_cast<std::uint64_t>(i);
  }
  return kept;
}
#endif

/// The k nearest points to p (k <= kMaxNeighbors) within sqrt(max_distance2), sorted by
/// distance, over the voxels walk(bound2, visit) visits; of equal distances the one visited first
/// is the nearer. Returns how many were found. Each candidate is one 64-bit key, the distance's
/// bits (ordered as the distances, which are >= 0) above its visit position, kept in a sorted
/// list in the thread's own registers and stack: one word moves per shift of an insertion.
template <typename Walk>
FARLIO_HD int knn_over(const ConstMapView& m, const Walk& walk, const Eigen::Vector3f& p, int k, float max_distance2,
                       std::int64_t* indices, float* distances2) {
  std::uint64_t best[kMaxNeighbors + 1];  // + a scratch slot (rank_first_voxel)
  std::int32_t walked[kNeighborVoxels];   // the voxels in visit order
  int voxels = 0, found = 0;
  float bound = max_distance2;
  const Eigen::Vector3f query = p;  // a copy: the list's stores cannot alias it
  walk([&] { return bound; },
       [&](std::int32_t v) {
         const auto rank = static_cast<std::uint64_t>(voxels);
         walked[voxels++] = v;
         const std::int32_t n = m.voxel_counts[v];
         const std::int64_t first = m.point_index(v, 0);
         // the bound and the count in locals over the voxel: captured by reference, they were
         // loaded and stored around every candidate (the list's stores might alias them)
         float voxel_bound = bound;
         int voxel_found = found;
         const int kk = k;
#if defined(__SSE2__) && !defined(FARLIO_ON_DEVICE)
         if (rank == 0 && n <= kRankedVoxelPoints) {
           found = rank_first_voxel(m, first, n, query, kk, voxel_bound, best);
           if (found == kk) bound = exec::float_from_bits(static_cast<std::uint32_t>(best[kk - 1] >> 32));
           return;
         }
#endif
         // distances of a block of points first, then the few that pass the bound are inserted
         for (std::int32_t j0 = 0; j0 < n; j0 += kDistanceBlock) {
           float block[kDistanceBlock];
           const std::int32_t len = block_distances2(m, first + j0, n - j0, query, block);
           for (std::int32_t j = 0; j < len; ++j) {
             if (!(block[j] < voxel_bound)) continue;
             const std::uint64_t key = (static_cast<std::uint64_t>(exec::float_bits(block[j])) << 32) |
                                       (rank << kSlotBits) | static_cast<std::uint64_t>(j0 + j);
             int pos = voxel_found < kk ? voxel_found++ : kk - 1;
             while (pos > 0 && best[pos - 1] > key) {
               best[pos] = best[pos - 1];
               --pos;
             }
             best[pos] = key;
             if (voxel_found == kk) {
               voxel_bound = exec::float_from_bits(static_cast<std::uint32_t>(best[kk - 1] >> 32));
             }
           }
         }
         bound = voxel_bound;
         found = voxel_found;
       });
  constexpr std::uint64_t kSlotMask = (std::uint64_t{1} << kSlotBits) - 1;
  for (int s = 0; s < found; ++s) {
    const std::uint64_t position = best[s] & 0xffffffffULL;
    indices[s] = m.point_index(walked[position >> kSlotBits], static_cast<std::int32_t>(position & kSlotMask));
    distances2[s] = exec::float_from_bits(static_cast<std::uint32_t>(best[s] >> 32));
  }
  return found;
}

/// The k nearest points to p (k <= kMaxNeighbors) within sqrt(max_distance2), sorted by
/// distance. Returns how many were found (< k when the neighbourhood holds fewer).
FARLIO_HD inline int knn_search(const ConstMapView& m, const Eigen::Vector3f& p, int k, float max_distance2,
                                std::int64_t* indices, float* distances2) {
  const auto walk = [&](const auto& bound, const auto& visit) { for_each_nearby_voxel(m, p, bound, visit); };
  return knn_over(m, walk, p, k, max_distance2, indices, distances2);
}

/// knn_search for a point of the centre voxel of `nb` (the same result, without the lookups).
FARLIO_HD inline int knn_search(const ConstMapView& m, const VoxelNeighborhood& nb, const Eigen::Vector3f& p, int k,
                                float max_distance2, std::int64_t* indices, float* distances2) {
  const auto walk = [&](const auto& bound, const auto& visit) { for_each_nearby_voxel(m, nb, p, bound, visit); };
  return knn_over(m, walk, p, k, max_distance2, indices, distances2);
}

}  // namespace farlio::map
