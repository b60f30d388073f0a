#pragma once
// The voxel hash map on the device: the layout of map_view.hpp (the host VoxelMap's), in
// buffers allocated once for a fixed voxel capacity. Updates run the shared per-voxel bodies of
// voxel_update.hpp in the CPU's order (candidates sorted by key, then input order; one thread
// per voxel group; new voxels taken from the free list, then the high-water mark, in key
// order), so the device map holds the same points in the same pool slots as the host map.
// The counts of an update stay on the device until the host reads them with a stage's other
// results in one wait: the *_async calls queue the work, post() queues the copy of their counts
// into the executor's read-back, settle() reads them after its wait. The plain calls do all three.
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
#include "farlio/cuda/read_back.hpp"
#include "farlio/exec/hd.hpp"
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

/// Sums over the voxel groups of one insertion.
struct InsertTotals {
  long long inserted = 0, spacing = 0, full = 0, covariances = 0, table_full = 0;
  FARLIO_HD InsertTotals& operator+=(const InsertTotals& o) {
    inserted += o.inserted;
    spacing += o.spacing;
    full += o.full;
    covariances += o.covariances;
    table_full += o.table_full;
    return *this;
  }
};

/// Voxels and their points, summed.
struct VoxelTotals {
  long long voxels = 0, points = 0;
  FARLIO_HD VoxelTotals& operator+=(const VoxelTotals& o) {
    voxels += o.voxels;
    points += o.points;
    return *this;
  }
};

/// What the *_async calls leave on the device, read back together.
struct DeviceMapCounts {
  InsertTotals insert;        ///< of the last insertion
  VoxelTotals near;           ///< voxels within range and their points (mean_points_per_voxel_async)
  long long points = 0;       ///< points stored (num_points_async)
  std::int32_t removed = 0;   ///< voxels freed by the last removal
  std::int32_t gathered = 0;  ///< points the last gather found
};

/// The results of the *_async calls since the last settle() (zero for those not called).
struct MapResults {
  map::InsertStats insert;
  std::size_t removed_voxels = 0;
  std::size_t gathered_points = 0;
  double mean_points_per_voxel = 0.0;
  std::size_t points = 0;
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
  /// (map::KeyWindow); a point farther away costs a second sort, never a wrong result. The host
  /// waits once, for the groups and the voxels to add; the counts come with settle().
  void insert_async(const Eigen::Vector3f* points, std::size_t n, const Eigen::Vector3f& origin,
                    const map::PointLimit& limit, double within_m = std::numeric_limits<double>::infinity(),
                    map::CovarianceUpdate covariances = map::CovarianceUpdate::Compute);
  map::InsertStats insert(const Eigen::Vector3f* points, std::size_t n, const Eigen::Vector3f& origin,
                          const map::PointLimit& limit, double within_m = std::numeric_limits<double>::infinity(),
                          map::CovarianceUpdate covariances = map::CovarianceUpdate::Compute);
  /// Removes voxels whose centre is farther than removal_radius_m from origin (no wait; the
  /// free list and the live count are brought up to date by settle()).
  void remove_far_async(const Eigen::Vector3f& origin);
  std::size_t remove_far(const Eigen::Vector3f& origin);
  /// Mean points per voxel over voxels whose centre lies within range_m of origin (0: none).
  void mean_points_per_voxel_async(const Eigen::Vector3f& origin, double range_m);
  [[nodiscard]] double mean_points_per_voxel(const Eigen::Vector3f& origin, double range_m);
  /// The points stored, counted on the device (settle()'s `points`).
  void num_points_async();
  [[nodiscard]] std::size_t num_points();
  /// Copies the stored points and covariances in pool order into device arrays of `capacity`
  /// elements; settle() throws CapacityError naming `parameter` when there are more (none is
  /// written beyond) and returns how many.
  void gather_async(Eigen::Vector4f* points, map::Cov3* covs, std::size_t capacity, const char* parameter);
  std::size_t gather(Eigen::Vector4f* points, map::Cov3* covs, std::size_t capacity, const char* parameter);
  /// Queues the copy of the counts of the *_async calls since the last settle().
  void post(ReadBack& read_back);
  /// After read_back.wait(): their results. Brings the host's bookkeeping up to date (and rehashes
  /// after a removal that leaves too many erased slots); throws CapacityError when the table or
  /// a gather's destination was too small.
  MapResults settle(const ReadBack& read_back);
  /// post(), the executor's read-back's wait, settle(): the queued work's results with one wait.
  MapResults read_results();
  /// Rebuilds the table from the live voxels (drops erased markers).
  void rehash();

  /// The kernels' window on the map: mutable for updates, read-only for searches.
  [[nodiscard]] map::MapView view();
  [[nodiscard]] map::ConstMapView view() const;
  [[nodiscard]] float spacing_m() const { return spacing_m_; }
  [[nodiscard]] std::size_t num_voxels() const { return live_voxels_; }
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

  /// What the *_async calls since the last settle() left to read.
  struct Pending {
    bool insert = false, removal = false, gather = false, mean = false, points = false;
    map::InsertStats insert_stats;  // the counts the host knows
    std::size_t gather_capacity = 0;
    const char* gather_parameter = "";
    ReadSlot<DeviceMapCounts> slot;
  };

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
  DeviceBuffer<DeviceMapCounts> device_counts_;
  Pending pending_;
};

}  // namespace farlio::cuda
