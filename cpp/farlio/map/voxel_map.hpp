#pragma once
// VoxelMap: the host owner of a voxel hash map (the layout of map_view.hpp) and its updates on
// the CPU executor: insertion with a per-voxel cap and a minimum spacing, covariances from the k
// nearest neighbours (eq. 1), removal of far voxels, and a pool that grows up to a hard limit
// (CapacityError beyond map.max_voxel_capacity). The decisions of an update (growth, rehash,
// new voxel slots, removal) are voxel_pool.hpp's, shared with the CUDA backend's DeviceVoxelMap.
//
// Updates are deterministic: points are grouped by voxel (in key order, then by input order)
// and each voxel's candidates are processed in that order by one task, so the map's contents do
// not depend on the thread count.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/key_grouping.hpp"
#include "farlio/map/map_snapshot.hpp"
#include "farlio/map/map_view.hpp"
#include "farlio/map/point_limit.hpp"
#include "farlio/map/voxel_pool.hpp"
#include "farlio/map/voxel_update.hpp"

namespace farlio::map {

/// The minimum distance between points of a voxel: config.point_spacing_m, or
/// voxel_size_m / sqrt(max_points_per_voxel) when that is 0.
double point_spacing_m(const VoxelMapConfig& config);

struct InsertStats {
  std::size_t candidates = 0;        ///< points offered
  std::size_t inserted = 0;          ///< points added
  std::size_t rejected_spacing = 0;  ///< closer than the spacing to a stored point
  std::size_t rejected_full = 0;     ///< their voxel had reached its limit
  std::size_t out_of_range = 0;      ///< outside the representable key range or non-finite
  std::size_t new_voxels = 0;
  std::size_t covariances_computed = 0;
};

class VoxelMap {
 public:
  VoxelMap(const VoxelMapConfig& config, exec::CpuExecutor& executor);

  /// Inserts world-frame points; the limit of each point depends on its distance to `origin`
  /// (the sensor position). Then computes covariances of the new points (and of all points of
  /// the voxels that changed, when config.refresh_covariances), unless `covariances` is Skip.
  InsertStats insert(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin, const PointLimit& limit,
                     CovarianceUpdate covariances = CovarianceUpdate::Compute);
  /// Removes voxels whose centre is farther than config.removal_radius_m from `origin`.
  std::size_t remove_far(const Eigen::Vector3f& origin);
  /// Removes everything (keeps the allocation).
  void clear();

  /// The kernels' window on the map: mutable for updates, read-only for searches.
  [[nodiscard]] MapView view();
  [[nodiscard]] ConstMapView view() const;
  [[nodiscard]] const VoxelMapConfig& config() const { return config_; }
  /// Minimum distance between two points of a voxel (config.point_spacing_m or
  /// voxel_size / sqrt(max_points_per_voxel)).
  [[nodiscard]] float spacing_m() const { return spacing_m_; }
  [[nodiscard]] std::size_t num_voxels() const { return live_voxels_; }
  [[nodiscard]] std::size_t num_points() const;
  [[nodiscard]] std::size_t voxel_capacity() const { return voxel_keys_.size(); }
  [[nodiscard]] std::size_t table_capacity() const { return slot_keys_.size(); }
  [[nodiscard]] std::size_t memory_bytes() const;

  /// A copy of the used part of the pool (voxels [0, high water)).
  [[nodiscard]] MapSnapshot snapshot() const;
  /// Calls f(point, covariance, covariance_valid) for every stored point (host only).
  void for_each_point(const std::function<void(const Eigen::Vector3f&, const Cov3&, bool)>& f) const;
  /// Mean number of points per voxel over voxels whose centre lies within `range_m` of
  /// `origin`; 0 when none does (used by the adaptive submap density).
  [[nodiscard]] double mean_points_per_voxel(const Eigen::Vector3f& origin, double range_m) const;

  /// Table size used before the first growth (a small table forces probing in tests).
  void set_table_capacity_for_testing(std::size_t slots);

 private:
  template <typename View, typename Self>
  static View view_of(Self& self);
  [[nodiscard]] PoolCounts counts() const;
  /// Grows the pool to hold `needed` voxels (doubling, up to map.max_voxel_capacity).
  void reserve_voxels(std::size_t needed);
  void rehash(std::size_t slots);
  // The steps of insert:
  /// 1. Groups the candidates by voxel (groups in key order, input order inside a voxel) into
  /// grouping_; returns the number of groups.
  std::size_t group_candidates(const std::vector<Eigen::Vector3f>& points);
  /// 2. The voxel of each group: the stored one, or a new one for each missing voxel (created
  /// serially, in key order: voxel_pool.hpp). Returns how many were created.
  std::size_t find_or_add_voxels(std::vector<std::int32_t>& group_voxel);
  /// 3. Inserts each voxel's candidates in order, with the cap and the spacing, one task a few
  /// voxels: each group's first new point slot and counts.
  void insert_groups(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin, const PointLimit& limit,
                     const std::vector<std::int32_t>& group_voxel, std::vector<std::int32_t>& first_new,
                     std::vector<GroupStats>& gstats);
  /// 4. Covariances of the new points (or of every point of a changed voxel), one task a voxel; a
  /// voxel that received none is skipped inside its task (no serial list of the changed ones).
  void update_group_covariances(const std::vector<std::int32_t>& group_voxel,
                                const std::vector<std::int32_t>& first_new, bool refresh);

  VoxelMapConfig config_;
  exec::CpuExecutor* executor_;  // not owned (a pointer keeps the map movable)
  float spacing_m_;
  // hash table
  std::vector<std::uint64_t> slot_keys_;
  std::vector<std::int32_t> slot_voxels_;
  std::size_t used_slots_ = 0;  // live + erased
  // voxel pool
  std::vector<std::uint64_t> voxel_keys_;  // kEmptyKey when free
  std::vector<std::int32_t> voxel_counts_;
  std::vector<Eigen::Vector4f> points_;
  std::vector<Cov3> covs_;
  std::vector<std::int32_t> free_voxels_;
  std::size_t high_water_ = 0;  // voxels [0, high_water_) have been used at least once
  std::size_t live_voxels_ = 0;
  // insertion scratch, kept across calls
  std::vector<std::uint64_t> keys_;
  KeyGrouping grouping_;
};

}  // namespace farlio::map
