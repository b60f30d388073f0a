#pragma once
// The per-voxel bodies of the map update, shared by the CPU executor (VoxelMap) and the CUDA
// backend: the key of a candidate point, the insertion of one voxel's candidates in their
// input order (cap and minimum spacing), the covariances of a voxel's points, and the voxel
// centre tests of removal and density. Both backends group the candidates by voxel the same
// way (sorted by key, then input order) and run one body per voxel, so they store the same
// points in the same order.
#include <Eigen/Core>
#include <cstdint>
#include <limits>

#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"
#include "farlio/map/covariance.hpp"
#include "farlio/map/map_view.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/point_limit.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::map {

/// The packed key of the voxel (or downsampling cell) of p, or kEmptyKey when p is not finite
/// or outside the key range: such points sort last and are dropped.
FARLIO_HD inline std::uint64_t point_key(const Eigen::Vector3f& p, float inv_cell_size) {
  if (!exec::all_finite(p)) return kEmptyKey;
  const VoxelCoord c = voxel_of(p, inv_cell_size);
  return in_key_range(c) ? pack_key(c) : kEmptyKey;
}

/// Stores the new voxel `key` in the free pool slot `voxel` (empty) and in the table; false when
/// the table is full.
FARLIO_HD inline bool add_voxel(const MapView& m, std::uint64_t key, std::int32_t voxel) {
  m.voxel_keys[voxel] = key;
  m.voxel_counts[voxel] = 0;
  return table_insert(m, key, spatial_hash(unpack_key(key)), voxel) >= 0;
}

/// Whether an insertion computes the covariances of the points it adds: Skip leaves them without
/// one (PointShape::NoCovariance), for a map whose covariances nothing will read (the frame map
/// of a scan with no submap to register against: the first).
enum class CovarianceUpdate { Compute, Skip };

/// What happened to one voxel's candidates.
struct GroupStats {
  std::int32_t inserted = 0, spacing = 0, full = 0;
};

struct InsertParams {
  Eigen::Vector3f origin;  ///< the sensor position (the limit depends on the distance to it)
  PointLimit limit;
  float spacing2;  ///< squared minimum distance between points of a voxel
};

/// The most points a voxel may hold when the candidate p arrives: the limit at p's distance from
/// the sensor, at most the pool's slots.
FARLIO_HD inline int candidate_cap(const MapView& m, const InsertParams& ip, const Eigen::Vector3f& p) {
  const int lim = ip.limit.at((p - ip.origin).norm());
  return lim < m.max_points_per_voxel ? lim : m.max_points_per_voxel;
}

/// Whether the stored point j of `voxel` is closer to p than the spacing.
FARLIO_HD inline bool too_close(const MapView& m, std::int32_t voxel, std::int32_t j, const Eigen::Vector3f& p,
                                const InsertParams& ip) {
  return (m.points[m.point_index(voxel, j)].head<3>() - p).squaredNorm() < ip.spacing2;
}

/// Stores p in slot j of `voxel` (no shape yet: its covariance comes after the insertion).
FARLIO_HD inline void store_point(const MapView& m, std::int32_t voxel, std::int32_t j, const Eigen::Vector3f& p) {
  m.points[m.point_index(voxel, j)] = Eigen::Vector4f(p.x(), p.y(), p.z(), 0.0f);
}

/// Inserts the candidates candidate(c), c in [begin, end), into `voxel` in that order: a
/// candidate is stored unless the voxel holds its limit or a stored point is closer than the
/// spacing. `*first_new` receives the voxel's count before the insertion. (CUDA makes the same
/// decisions with a warp a voxel, the lanes testing the stored points together.)
template <typename Candidate>
FARLIO_HD GroupStats insert_voxel_group(const MapView& m, std::int32_t voxel, const Candidate& candidate,
                                        std::int64_t begin, std::int64_t end, const InsertParams& ip,
                                        std::int32_t* first_new) {
  GroupStats s;
  std::int32_t count = m.voxel_counts[voxel];
  *first_new = count;
  for (std::int64_t c = begin; c < end; ++c) {
    const Eigen::Vector3f p = candidate(c);
    if (count >= candidate_cap(m, ip, p)) {
      ++s.full;
      continue;
    }
    bool close = false;
    for (std::int32_t j = 0; j < count && !close; ++j) close = too_close(m, voxel, j, p, ip);
    if (close) {
      ++s.spacing;
      continue;
    }
    store_point(m, voxel, count, p);
    ++count;
    ++s.inserted;
  }
  m.voxel_counts[voxel] = count;
  return s;
}

/// The points [begin, end) of a voxel whose covariances an insertion (re)computes: none when it
/// received no point (count == first_new), else the new ones, or all when `refresh`.
struct PointRange {
  std::int32_t begin = 0, end = 0;
  [[nodiscard]] FARLIO_HD std::int32_t size() const { return end - begin; }
};
FARLIO_HD inline PointRange covariance_points(std::int32_t count, std::int32_t first_new, bool refresh) {
  if (count == first_new) return {};
  return {refresh ? 0 : first_new, count};
}

/// No distance limit for the covariance neighbours (the 27 voxels bound them).
inline constexpr float kUnboundedDistance2 = std::numeric_limits<float>::max();

/// Covariance (eq. 1) of point j of `voxel` from its k nearest neighbours found by
/// knn(p, idx, d2), and its shape in w (map::PointShape: no covariance with fewer than k
/// neighbours, else surface or line by `line_ratio`).
template <typename Knn>
FARLIO_HD void point_covariance(const MapView& m, std::int32_t voxel, std::int32_t j, int k, float epsilon,
                                float line_ratio, const Knn& knn) {
  std::int64_t idx[kMaxNeighbors];
  float d2[kMaxNeighbors];
  const std::int64_t pi = m.point_index(voxel, j);
  const Eigen::Vector3f p = m.points[pi].head<3>();
  const int found = knn(p, idx, d2);
  if (found < k) {
    m.points[pi].w() = shape_code(PointShape::NoCovariance);
    return;
  }
  CovarianceAccumulator acc(p);
  for (int n = 0; n < found; ++n) acc.add(m.points[idx[n]].head<3>());
  const Eigen::Matrix3f cov = regularize_frobenius(acc.covariance(), epsilon);
  m.covs[pi] = Cov3::from(cov);
  m.points[pi].w() = shape_code(classify_shape(cov, line_ratio));
}

/// The covariance of point j of `voxel` from the 27 voxels around it, looked up before (`nb`):
/// the CPU loops over a voxel's points (update_voxel_covariances), CUDA runs one point a lane
/// of the warp that looked the voxels up.
FARLIO_HD inline void update_point_covariance(const MapView& m, const VoxelNeighborhood& nb, std::int32_t voxel,
                                              std::int32_t j, int k, float epsilon, float line_ratio) {
  point_covariance(m, voxel, j, k, epsilon, line_ratio, [&](const Eigen::Vector3f& p, std::int64_t* idx, float* d2) {
    return knn_search(m, nb, p, k, kUnboundedDistance2, idx, d2);
  });
}

/// Covariances of the points `points` of `voxel` (one CPU task a voxel): the 27 voxels around
/// it are looked up once for all of them.
FARLIO_HD inline void update_voxel_covariances(const MapView& m, std::int32_t voxel, const PointRange& points, int k,
                                               float epsilon, float line_ratio) {
  if (points.size() == 0) return;
  const VoxelNeighborhood nb = voxel_neighborhood(m, unpack_key(m.voxel_keys[voxel]));
  for (std::int32_t j = points.begin; j < points.end; ++j)
    update_point_covariance(m, nb, voxel, j, k, epsilon, line_ratio);
}

/// Squared distance (double) from `origin` to the centre of the voxel with this key.
FARLIO_HD inline double voxel_centre_distance2(std::uint64_t key, const Eigen::Vector3d& origin, double voxel_size) {
  const VoxelCoord c = unpack_key(key);
  const Eigen::Vector3d centre = (c.cast<double>() + Eigen::Vector3d::Constant(0.5)) * voxel_size;
  return (centre - origin).squaredNorm();
}

/// Whether remove_far removes the voxel of this pool entry: a live voxel whose centre is farther
/// than sqrt(radius2) from origin.
FARLIO_HD inline bool voxel_is_far(std::uint64_t key, const Eigen::Vector3d& origin, double radius2,
                                   double voxel_size) {
  return key != kEmptyKey && voxel_centre_distance2(key, origin, voxel_size) > radius2;
}

}  // namespace farlio::map
