#pragma once
// The voxel hash map on the device: the layout of map_view.hpp (the host VoxelMap's), in
// buffers allocated once for a fixed voxel capacity. Updates run the shared per-voxel bodies of
// voxel_update.hpp in the CPU's order (candidates sorted by key, then input order; one thread
// per voxel group; new voxels taken from the free list, then the high-water mark, in key
// order), so the device map holds the same points in the same pool slots as the host map.
// Plain C++ header; the launches are in device_voxel_map.cu.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/cuda/cuda_executor.hpp"
#include "farlio/cuda/device_algorithms.hpp"
#include "farlio/cuda/device_buffer.hpp"
#include "farlio/cuda/map_scratch.hpp"
#include "farlio/map/map_snapshot.hpp"
#include "farlio/map/map_view.hpp"
#include "farlio/map/point_limit.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_pool.hpp"

namespace farlio::cuda {

/// k nearest neighbours of several queries, k entries per query (tests and tools); the ranks
/// past found[q] hold index -1 and a NaN distance.
struct KnnResults {
  int k = 0;
  std::vector<int> found;
  std::vector<std::int64_t> indices;
  std::vector<float> distances2;
};

class DeviceVoxelMap {
 public:
  /// `capacity_parameter` is the config field that sets voxel_capacity (named in errors).
  DeviceVoxelMap(const VoxelMapConfig& config, std::size_t voxel_capacity, std::string capacity_parameter,
                 CudaExecutor& executor, DeviceAlgorithms& algorithms, MapScratch& scratch);

  /// Takes new parameters (same max_points_per_voxel) and empties the map; allocates nothing.
  void reconfigure(const VoxelMapConfig& config);
  void clear();
  /// Inserts n device points (world frame), as VoxelMap::insert. `within_m`: how far from origin
  /// the points are expected (a scan's crop range): their voxels are then sorted on short keys
  /// (map::KeyWindow); a point farther away costs a second sort, never a wrong result.
  map::InsertStats insert(const Eigen::Vector3f* points, std::size_t n, const Eigen::Vector3f& origin,
                          const map::PointLimit& limit, double within_m = std::numeric_limits<double>::infinity(),
                          map::CovarianceUpdate covariances = map::CovarianceUpdate::Compute);
  /// Removes voxels whose centre is farther than removal_radius_m from origin.
  std::size_t remove_far(const Eigen::Vector3f& origin);
  /// Mean points per voxel over voxels whose centre lies within range_m of origin (0: none).
  [[nodiscard]] double mean_points_per_voxel(const Eigen::Vector3f& origin, double range_m) const;
  /// Copies the stored points and covariances in pool order into device arrays of `capacity`
  /// elements (throws CapacityError naming `parameter` beyond); returns how many.
  std::size_t gather(Eigen::Vector4f* points, map::Cov3* covs, std::size_t capacity, const char* parameter);
  /// Rebuilds the table from the live voxels (drops erased markers).
  void rehash();

  /// The kernels' window on the map: mutable for updates, read-only for searches.
  [[nodiscard]] map::MapView view();
  [[nodiscard]] map::ConstMapView view() const;
  [[nodiscard]] float spacing_m() const { return spacing_m_; }
  [[nodiscard]] std::size_t num_voxels() const { return live_voxels_; }
  [[nodiscard]] std::size_t num_points() const;
  [[nodiscard]] std::size_t voxel_capacity() const { return capacity_; }
  [[nodiscard]] std::size_t memory_bytes() const;
  /// A host copy of voxels [0, high water).
  [[nodiscard]] map::MapSnapshot snapshot() const;
  /// The k nearest stored points of each host query (allocates: for tests and tools).
  [[nodiscard]] KnnResults knn(const std::vector<Eigen::Vector3f>& queries, int k, float max_distance2) const;

 private:
  template <typename View, typename Self>
  static View view_of(Self& self);
  [[nodiscard]] map::PoolCounts counts() const;

  VoxelMapConfig config_;
  std::size_t capacity_;
  std::string capacity_parameter_;
  CudaExecutor* executor_;
  DeviceAlgorithms* algorithms_;
  MapScratch* scratch_;
  float spacing_m_;
  // table
  DeviceBuffer<std::uint64_t> slot_keys_;
  DeviceBuffer<std::int32_t> slot_voxels_;
  std::size_t used_slots_ = 0;  // live + erased
  // pool
  DeviceBuffer<std::uint64_t> voxel_keys_;
  DeviceBuffer<std::int32_t> voxel_counts_;
  DeviceBuffer<Eigen::Vector4f> points_;
  DeviceBuffer<map::Cov3> covs_;
  DeviceBuffer<std::int32_t> free_voxels_;
  std::size_t free_count_ = 0;
  std::size_t high_water_ = 0;
  std::size_t live_voxels_ = 0;
};

}  // namespace farlio::cuda
