#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "farlio/core/config_fields.hpp"
#include "farlio/cuda/cuda_executor.cuh"
#include "farlio/cuda/device_voxel_map.hpp"
#include "farlio/cuda/warp_search.cuh"
#include "farlio/map/voxel_update.hpp"

namespace farlio::cuda {
namespace {

std::int32_t read_scalar(const std::int32_t* device_value, cudaStream_t stream) {
  std::int32_t v = 0;
  FARLIO_CUDA_CHECK(cudaMemcpyAsync(&v, device_value, sizeof(v), cudaMemcpyDeviceToHost, stream));
  FARLIO_CUDA_CHECK(cudaStreamSynchronize(stream));
  return v;
}

/// Each group's stored voxel (-1 when missing) and, in key order, the rank of each missing one
/// (an exclusive sum of the misses): queued over the upper bound of n groups (the count is on the
/// device, in scalars[kScalarGroups]); rank[n] receives the number of misses.
void find_group_voxels(const map::MapView& v, MapScratch& s, CudaExecutor& ex, DeviceAlgorithms& algorithms,
                       std::size_t n) {
  const std::uint64_t* sorted_keys = s.sorted_keys.data();
  const std::int32_t* group_start = s.group_start.data();
  const std::int32_t* scalars = s.scalars.data();
  std::int32_t* group_voxel = s.group_voxel.data();
  std::int32_t* missing = s.missing.data();
  std::int32_t* rank = s.rank.data();
  ex.for_each(n + 1, [=] __device__(std::size_t g) {
    if (g >= static_cast<std::size_t>(scalars[kScalarGroups])) {
      missing[g] = 0;  // beyond the groups: the sum stops counting
      return;
    }
    const std::uint64_t key = sorted_keys[group_start[g]];
    const std::int32_t vox = map::table_find(v, key, map::spatial_hash(map::unpack_key(key)));
    group_voxel[g] = vox;
    missing[g] = vox < 0 ? 1 : 0;
  });
  algorithms.exclusive_sum(missing, rank, n + 1);
}

/// A new voxel for each missing group, in the host's allocation order (voxel_pool.hpp), one
/// thread a group; a voxel the table has no slot for counts in `table_full`.
void add_group_voxels(const map::MapView& v, MapScratch& s, CudaExecutor& ex, std::size_t groups,
                      const std::int32_t* free_list, std::size_t free_count, std::size_t from_free_list,
                      std::size_t high_water, std::int32_t* table_full) {
  const std::uint64_t* sorted_keys = s.sorted_keys.data();
  const std::int32_t* group_start = s.group_start.data();
  std::int32_t* group_voxel = s.group_voxel.data();
  const std::int32_t* missing = s.missing.data();
  const std::int32_t* rank = s.rank.data();
  ex.for_each(groups, [=] __device__(std::size_t g) {
    if (!missing[g]) return;
    const std::int32_t vox = map::new_voxel_slot(rank[g], free_list, free_count, from_free_list, high_water);
    group_voxel[g] = vox;
    if (!map::add_voxel(v, sorted_keys[group_start[g]], vox)) exec::atomic_add(table_full, 1);
  });
}

constexpr unsigned kGroupWarps = 4;  // a block's warps: a voxel group each
constexpr std::size_t kMaxGroupBlocks = 65535;

/// Blocks of kGroupWarps warps for one warp a group (grid-stride beyond kMaxGroupBlocks).
unsigned group_blocks(std::size_t groups) {
  return static_cast<unsigned>(std::min((groups + kGroupWarps - 1) / kGroupWarps, kMaxGroupBlocks));
}

/// Inserts each group's candidates in order, one warp a group: the candidates one after the
/// other (a candidate's spacing test depends on the points stored before it), each tested
/// against the voxel's stored points by all lanes at once. The decisions of
/// map::insert_voxel_group (the CPU's loop, one stored point after the other), with its bodies.
__global__ void __launch_bounds__(kGroupWarps* kWarpLanes)
    group_insert_kernel(map::MapView v, const Eigen::Vector3f* sorted, const std::int32_t* group_start,
                        const std::int32_t* group_voxel, std::size_t groups, map::InsertParams ip,
                        std::int32_t* first_new, map::GroupStats* gstats) {
  const auto lane = static_cast<std::int32_t>(threadIdx.x % kWarpLanes);
  const unsigned warp = threadIdx.x / kWarpLanes;
  const std::size_t stride = static_cast<std::size_t>(gridDim.x) * kGroupWarps;
  for (std::size_t g = static_cast<std::size_t>(blockIdx.x) * kGroupWarps + warp; g < groups; g += stride) {
    const std::int32_t vox = group_voxel[g];
    const std::int32_t before = v.voxel_counts[vox];
    std::int32_t count = before;
    map::GroupStats s;
    for (std::int32_t c = group_start[g]; c < group_start[g + 1]; ++c) {  // the same c in every lane
      const Eigen::Vector3f p = sorted[c];
      if (count >= map::candidate_cap(v, ip, p)) {
        ++s.full;
        continue;
      }
      bool close = false;
      for (std::int32_t j = lane; j < count && !close; j += static_cast<std::int32_t>(kWarpLanes)) {
        close = map::too_close(v, vox, j, p, ip);
      }
      if (__any_sync(kFullWarp, close)) {
        ++s.spacing;
        continue;
      }
      if (lane == 0) map::store_point(v, vox, count, p);
      __syncwarp();  // the stored point is visible to every lane before the next candidate's test
      ++count;
      ++s.inserted;
    }
    if (lane == 0) {
      v.voxel_counts[vox] = count;
      first_new[g] = before;
      gstats[g] = s;
    }
  }
}

/// Inserts each voxel's candidates in order, with the cap and the spacing (one warp a voxel;
/// `candidates`: the sorted ones that have a voxel, the groups' points),
/// and sums the groups' counts (the covariances to compute when `compute`) with the table's
/// failed insertions into *totals (on the device).
void insert_groups(const map::MapView& v, MapScratch& s, CudaExecutor& ex, const Eigen::Vector3f* points,
                   std::size_t candidates, std::size_t groups, const map::InsertParams& ip, bool compute, bool refresh,
                   const std::int32_t* table_full, InsertTotals* totals) {
  const std::int32_t* order = s.sorted_order.data();
  const std::int32_t* group_start = s.group_start.data();
  const std::int32_t* group_voxel = s.group_voxel.data();
  std::int32_t* first_new = s.first_new.data();
  map::GroupStats* gstats = s.group_stats.data();
  // the candidates in sorted order first, one thread each: a group's warp then reads its
  // candidates one after the other from contiguous memory, not from all over the input
  Eigen::Vector3f* sorted = s.sorted_points.data();
  ex.for_each(candidates, [=] __device__(std::size_t c) { sorted[c] = points[order[c]]; });
  group_insert_kernel<<<group_blocks(groups), kGroupWarps * kWarpLanes, 0, ex.stream()>>>(
      v, sorted, group_start, group_voxel, groups, ip, first_new, gstats);
  FARLIO_CUDA_CHECK(cudaGetLastError());
  ex.reduce_into(
      groups, InsertTotals{},
      [=] __device__(std::size_t g) {
        InsertTotals t;
        t.inserted = gstats[g].inserted;
        t.spacing = gstats[g].spacing;
        t.full = gstats[g].full;
        t.covariances =
            compute ? map::covariance_points(v.voxel_counts[group_voxel[g]], first_new[g], refresh).size() : 0;
        if (g == 0) t.table_full = *table_full;
        return t;
      },
      Add{}, totals);
}

/// Covariances of the new points (or of every point of a changed voxel): one warp a group. Its
/// lanes look up the 27 voxels around the group's voxel together, then each lane computes a
/// point's covariance from them (map::update_point_covariance; the CPU runs the same body in a
/// loop over the voxel's points, one task a voxel).
__global__ void __launch_bounds__(kGroupWarps* kWarpLanes)
    group_covariance_kernel(map::MapView v, const std::int32_t* group_voxel, const std::int32_t* first_new,
                            std::size_t groups, int k, float eps, float line_ratio, bool refresh) {
  __shared__ std::int32_t found[kGroupWarps][map::kNeighborVoxels];
  const unsigned lane = threadIdx.x % kWarpLanes, warp = threadIdx.x / kWarpLanes;
  const std::size_t stride = static_cast<std::size_t>(gridDim.x) * kGroupWarps;
  for (std::size_t g = static_cast<std::size_t>(blockIdx.x) * kGroupWarps + warp; g < groups; g += stride) {
    const std::int32_t vox = group_voxel[g];
    const map::PointRange r = map::covariance_points(v.voxel_counts[vox], first_new[g], refresh);
    if (r.size() == 0) continue;  // the whole warp: one group
    map::VoxelNeighborhood nb;
    nb.centre = map::unpack_key(v.voxel_keys[vox]);
    if (lane < map::kNeighborVoxels) {
      found[warp][lane] = map::table_find(v, map::neighbor_voxel(nb.centre, static_cast<int>(lane)));
    }
    __syncwarp();
    for (int n = 0; n < map::kNeighborVoxels; ++n) nb.voxels[n] = found[warp][n];
    __syncwarp();  // read before the next group's lookups
    for (std::int32_t j = r.begin + static_cast<std::int32_t>(lane); j < r.end; j += kWarpLanes) {
      map::update_point_covariance(v, nb, vox, j, k, eps, line_ratio);
    }
  }
}

void update_group_covariances(const map::MapView& v, MapScratch& s, CudaExecutor& ex, std::size_t groups,
                              const VoxelMapConfig& config, bool refresh) {
  group_covariance_kernel<<<group_blocks(groups), kGroupWarps * kWarpLanes, 0, ex.stream()>>>(
      v, s.group_voxel.data(), s.first_new.data(), groups, config.covariance_neighbors,
      static_cast<float>(config.covariance_epsilon), static_cast<float>(config.line_eigenvalue_ratio), refresh);
  FARLIO_CUDA_CHECK(cudaGetLastError());
}

}  // namespace

DeviceVoxelMap::DeviceVoxelMap(const VoxelMapConfig& config, std::size_t voxel_capacity, std::string capacity_parameter,
                               CudaExecutor& executor, DeviceAlgorithms& algorithms, MapScratch& scratch)
    : config_(config),
      capacity_(voxel_capacity),
      capacity_parameter_(std::move(capacity_parameter)),
      executor_(&executor),
      algorithms_(&algorithms),
      scratch_(&scratch),
      spacing_m_(static_cast<float>(map::point_spacing_m(config))),
      slot_keys_(map::table_capacity_for(voxel_capacity), "table slots"),
      slot_voxels_(map::table_capacity_for(voxel_capacity), "table slots"),
      voxel_keys_(voxel_capacity, "voxels"),
      voxel_counts_(voxel_capacity, "voxels"),
      points_(voxel_capacity * static_cast<std::size_t>(config.max_points_per_voxel), "map points"),
      covs_(voxel_capacity * static_cast<std::size_t>(config.max_points_per_voxel), "map points"),
      free_voxels_(voxel_capacity, "voxels"),
      device_counts_(1, "map counts") {
  validate_config(config);
  if (voxel_capacity == 0 || voxel_capacity >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    throw CapacityError("CUDA backend: " + capacity_parameter_ + " must be in [1, 2^31)");
  }
  scratch.keys.require(voxel_capacity + 1, "cuda.max_scan_points");  // the scratch serves removals too
  high_water_ = capacity_;  // so that clear() empties the whole pool once: empty keys, no points
  clear();
  // the point slots once, as the CPU pool's: a snapshot copies whole voxels, never memory nothing
  // wrote (compute-sanitizer initcheck)
  FARLIO_CUDA_CHECK(cudaMemsetAsync(points_.data(), 0, points_.bytes(), executor.stream()));
  FARLIO_CUDA_CHECK(cudaMemsetAsync(covs_.data(), 0, covs_.bytes(), executor.stream()));
  // every byte defined: post() copies the whole struct
  FARLIO_CUDA_CHECK(cudaMemsetAsync(device_counts_.data(), 0, device_counts_.bytes(), executor.stream()));
}

void DeviceVoxelMap::reconfigure(const VoxelMapConfig& config) {
  if (config.max_points_per_voxel != config_.max_points_per_voxel) {
    throw std::invalid_argument(
        "DeviceVoxelMap::reconfigure: max_points_per_voxel cannot change (buffers are preallocated)");
  }
  validate_config(config);
  config_ = config;
  spacing_m_ = static_cast<float>(map::point_spacing_m(config));
  clear();
}

template <typename View, typename Self>
View DeviceVoxelMap::view_of(Self& self) {
  return map::make_map_view<View>(self.slot_keys_.data(), self.slot_voxels_.data(), self.slot_keys_.capacity(),
                                  self.voxel_keys_.data(), self.voxel_counts_.data(), self.points_.data(),
                                  self.covs_.data(), self.config_.max_points_per_voxel, self.config_.voxel_size_m);
}

map::MapView DeviceVoxelMap::view() { return view_of<map::MapView>(*this); }
map::ConstMapView DeviceVoxelMap::view() const { return view_of<map::ConstMapView>(*this); }

map::PoolCounts DeviceVoxelMap::counts() const {
  return {high_water_, free_count_, live_voxels_, used_slots_, slot_keys_.capacity()};
}

void DeviceVoxelMap::clear() {
  const cudaStream_t s = executor_->stream();
  FARLIO_CUDA_CHECK(cudaMemsetAsync(slot_keys_.data(), 0xFF, slot_keys_.bytes(), s));  // all kEmptyKey
  FARLIO_CUDA_CHECK(cudaMemsetAsync(voxel_keys_.data(), 0xFF, high_water_ * sizeof(std::uint64_t), s));
  FARLIO_CUDA_CHECK(cudaMemsetAsync(voxel_counts_.data(), 0, high_water_ * sizeof(std::int32_t), s));
  free_count_ = high_water_ = live_voxels_ = used_slots_ = 0;
}

void DeviceVoxelMap::rehash() {
  FARLIO_CUDA_CHECK(cudaMemsetAsync(slot_keys_.data(), 0xFF, slot_keys_.bytes(), executor_->stream()));
  FARLIO_CUDA_CHECK(cudaMemsetAsync(scratch_->scalars.data(), 0, scratch_->scalars.bytes(), executor_->stream()));
  const map::MapView v = view();
  std::int32_t* table_full = scratch_->scalars.data() + kScalarTableFull;
  executor_->for_each(high_water_, [=] __device__(std::size_t i) {
    const std::uint64_t key = v.voxel_keys[i];
    if (key == map::kEmptyKey) return;
    if (map::table_insert(v, key, map::spatial_hash(map::unpack_key(key)), static_cast<std::int32_t>(i)) < 0) {
      exec::atomic_add(table_full, 1);
    }
  });
  if (read_scalar(table_full, executor_->stream()) > 0) {
    throw CapacityError("CUDA backend: the voxel table is full while rehashing; raise " + capacity_parameter_);
  }
  used_slots_ = live_voxels_;
}

void DeviceVoxelMap::insert_async(const Eigen::Vector3f* points, std::size_t n, const Eigen::Vector3f& origin,
                                  const map::PointLimit& limit, double within_m, map::CovarianceUpdate covariances) {
  pending_.insert = true;
  map::InsertStats& stats = pending_.insert_stats;
  stats = map::InsertStats{};
  stats.candidates = n;
  // the device totals of an insertion that adds nothing
  FARLIO_CUDA_CHECK(cudaMemsetAsync(&device_counts_.data()->insert, 0, sizeof(InsertTotals), executor_->stream()));
  if (n == 0) return;
  MapScratch& s = *scratch_;
  CudaExecutor& ex = *executor_;
  s.keys.require(n + 1, "cuda.max_scan_points");

  // 1. group the candidates by voxel, in input order inside a voxel, and find their voxels; new
  //    ones are numbered in key order (exclusive sum of the misses). One wait for both.
  const float inv_voxel = static_cast<float>(1.0 / config_.voxel_size_m);
  std::uint64_t* keys = s.keys.data();
  ex.for_each(n, [=] __device__(std::size_t i) { keys[i] = map::point_key(points[i], inv_voxel); });
  const map::MapView v = view();
  ReadSlot<std::int32_t> misses;
  const auto window = map::KeyWindow::around(origin.cast<double>(), within_m, 1.0 / config_.voxel_size_m);
  const SortedGroups sorted = sort_into_groups(s, ex, *algorithms_, n, window, [&](ReadBack& rb) {
    find_group_voxels(v, s, ex, *algorithms_, n);
    misses = rb.post(s.rank.data() + n);
  });
  const std::size_t groups = sorted.groups;
  stats.out_of_range = n - sorted.valid;
  if (groups == 0) return;
  const auto new_voxels = static_cast<std::size_t>(ex.read_back().value(misses));

  // 2. the new voxels take their slots
  std::int32_t* table_full = s.scalars.data() + kScalarTableFull;
  FARLIO_CUDA_CHECK(cudaMemsetAsync(table_full, 0, sizeof(std::int32_t), ex.stream()));
  if (new_voxels > 0) {
    const map::InsertionPlan plan = map::plan_insertion(counts(), new_voxels, capacity_, capacity_parameter_);
    if (plan.rehash_slots > 0) {  // the device table has its one size: drop the erased slots in place
      if (plan.rehash_slots != slot_keys_.capacity()) {
        throw CapacityError("CUDA backend: the voxel table cannot grow; raise " + capacity_parameter_);
      }
      rehash();
    }
    add_group_voxels(v, s, ex, groups, free_voxels_.data(), free_count_, plan.from_free_list, high_water_, table_full);
    free_count_ -= plan.from_free_list;
    high_water_ = plan.high_water;
    live_voxels_ += new_voxels;
    used_slots_ += new_voxels;
    stats.new_voxels = new_voxels;
  }

  // 3. insert each voxel's candidates in order, with the cap and the spacing
  const bool refresh = config_.refresh_covariances;
  const bool compute = covariances == map::CovarianceUpdate::Compute;
  const map::InsertParams ip{origin, limit, spacing_m_ * spacing_m_};
  insert_groups(v, s, ex, points, sorted.valid, groups, ip, compute, refresh, table_full,
                &device_counts_.data()->insert);

  // 4. covariances of the new points (or of every point of a changed voxel)
  if (compute) update_group_covariances(v, s, ex, groups, config_, refresh);
}

map::InsertStats DeviceVoxelMap::insert(const Eigen::Vector3f* points, std::size_t n, const Eigen::Vector3f& origin,
                                        const map::PointLimit& limit, double within_m,
                                        map::CovarianceUpdate covariances) {
  insert_async(points, n, origin, limit, within_m, covariances);
  return read_results().insert;
}

void DeviceVoxelMap::remove_far_async(const Eigen::Vector3f& origin) {
  if (!map::removal_applies(config_, high_water_)) return;
  pending_.removal = true;
  const double r2 = config_.removal_radius_m * config_.removal_radius_m;
  const double vs = config_.voxel_size_m;
  const Eigen::Vector3d o = origin.cast<double>();
  const map::MapView v = view();
  std::uint8_t* flags = scratch_->flags.data();
  executor_->for_each(high_water_, [=] __device__(std::size_t i) {
    const std::uint64_t key = v.voxel_keys[i];
    const bool far = map::voxel_is_far(key, o, r2, vs);
    flags[i] = far;
    if (!far) return;
    map::table_erase(v, key, map::spatial_hash(map::unpack_key(key)));
    v.voxel_keys[i] = map::kEmptyKey;
    v.voxel_counts[i] = 0;
  });
  // freed voxels join the free list in increasing order, as on the CPU
  algorithms_->select_flagged(scratch_->iota.data(), flags, free_voxels_.data() + free_count_,
                              &device_counts_.data()->removed, high_water_);
}

std::size_t DeviceVoxelMap::remove_far(const Eigen::Vector3f& origin) {
  remove_far_async(origin);
  return read_results().removed_voxels;
}

void DeviceVoxelMap::mean_points_per_voxel_async(const Eigen::Vector3f& origin, double range_m) {
  pending_.mean = true;
  const map::ConstMapView v = view();
  const double vs = config_.voxel_size_m;
  const Eigen::Vector3d o = origin.cast<double>();
  executor_->reduce_into(
      high_water_, VoxelTotals{},
      [=] __device__(std::size_t i) {
        VoxelTotals r;
        const std::uint64_t key = v.voxel_keys[i];
        if (key == map::kEmptyKey || sqrt(map::voxel_centre_distance2(key, o, vs)) > range_m) return r;
        r.voxels = 1;
        r.points = v.voxel_counts[i];
        return r;
      },
      Add{}, &device_counts_.data()->near);
}

double DeviceVoxelMap::mean_points_per_voxel(const Eigen::Vector3f& origin, double range_m) {
  mean_points_per_voxel_async(origin, range_m);
  return read_results().mean_points_per_voxel;
}

void DeviceVoxelMap::num_points_async() {
  pending_.points = true;
  const std::int32_t* counts = voxel_counts_.data();
  executor_->reduce_into(
      high_water_, 0LL, [=] __device__(std::size_t i) { return static_cast<long long>(counts[i]); }, Add{},
      &device_counts_.data()->points);
}

std::size_t DeviceVoxelMap::num_points() {
  num_points_async();
  return read_results().points;
}

void DeviceVoxelMap::gather_async(Eigen::Vector4f* out_points, map::Cov3* out_covs, std::size_t capacity,
                                  const char* parameter) {
  pending_.gather = true;
  pending_.gather_capacity = capacity;
  pending_.gather_parameter = parameter;
  std::int32_t* gathered = &device_counts_.data()->gathered;
  if (high_water_ == 0) {
    FARLIO_CUDA_CHECK(cudaMemsetAsync(gathered, 0, sizeof(std::int32_t), executor_->stream()));
    return;
  }
  const map::ConstMapView v = view();
  std::int32_t* counts = scratch_->missing.data();
  std::int32_t* offsets = scratch_->rank.data();
  const std::size_t hw = high_water_;
  executor_->for_each(hw + 1, [=] __device__(std::size_t i) { counts[i] = i < hw ? v.voxel_counts[i] : 0; });
  algorithms_->exclusive_sum(counts, offsets, hw + 1);
  // the total is known on the device only: no point is written beyond the capacity
  // one thread a point slot
  const auto limit = static_cast<std::int64_t>(capacity);
  const auto slots = static_cast<std::size_t>(config_.max_points_per_voxel);
  executor_->for_each(hw * slots, [=] __device__(std::size_t t) {
    if (t == 0) *gathered = offsets[hw];
    const auto vox = static_cast<std::int32_t>(t / slots);
    const auto j = static_cast<std::int32_t>(t % slots);
    if (j >= v.voxel_counts[vox] || offsets[vox] + j >= limit) return;
    out_points[offsets[vox] + j] = v.points[v.point_index(vox, j)];
    out_covs[offsets[vox] + j] = v.covs[v.point_index(vox, j)];
  });
}

std::size_t DeviceVoxelMap::gather(Eigen::Vector4f* out_points, map::Cov3* out_covs, std::size_t capacity,
                                   const char* parameter) {
  gather_async(out_points, out_covs, capacity, parameter);
  return read_results().gathered_points;
}

void DeviceVoxelMap::post(ReadBack& read_back) { pending_.slot = read_back.post(device_counts_.data()); }

MapResults DeviceVoxelMap::settle(const ReadBack& read_back) {
  const Pending done = std::exchange(pending_, Pending{});
  const DeviceMapCounts c = read_back.value(done.slot);
  MapResults r;
  if (done.insert) {
    if (c.insert.table_full > 0) {
      throw CapacityError("CUDA backend: the voxel table is full; raise " + capacity_parameter_);
    }
    r.insert = done.insert_stats;
    r.insert.inserted = static_cast<std::size_t>(c.insert.inserted);
    r.insert.rejected_spacing = static_cast<std::size_t>(c.insert.spacing);
    r.insert.rejected_full = static_cast<std::size_t>(c.insert.full);
    r.insert.covariances_computed = static_cast<std::size_t>(c.insert.covariances);
  }
  if (done.removal) {
    r.removed_voxels = static_cast<std::size_t>(c.removed);
    free_count_ += r.removed_voxels;
    live_voxels_ -= r.removed_voxels;
    if (map::rehash_after_removal(counts())) rehash();
  }
  if (done.gather) {
    r.gathered_points = static_cast<std::size_t>(c.gathered);
    if (r.gathered_points > done.gather_capacity) {
      throw CapacityError("CUDA backend: " + std::to_string(r.gathered_points) +
                          " source points exceed the device buffer of " + std::to_string(done.gather_capacity) +
                          "; raise " + done.gather_parameter);
    }
  }
  if (done.mean && c.near.voxels > 0) {
    r.mean_points_per_voxel = static_cast<double>(c.near.points) / static_cast<double>(c.near.voxels);
  }
  if (done.points) r.points = static_cast<std::size_t>(c.points);
  return r;
}

MapResults DeviceVoxelMap::read_results() {
  ReadBack& rb = executor_->read_back();
  rb.clear();
  post(rb);
  rb.wait();
  return settle(rb);
}

std::size_t DeviceVoxelMap::memory_bytes() const {
  return slot_keys_.bytes() + slot_voxels_.bytes() + voxel_keys_.bytes() + voxel_counts_.bytes() + points_.bytes() +
         covs_.bytes() + free_voxels_.bytes();
}

map::MapSnapshot DeviceVoxelMap::snapshot() const {
  const auto n = static_cast<std::size_t>(config_.max_points_per_voxel);
  map::MapSnapshot s;
  s.max_points_per_voxel = config_.max_points_per_voxel;
  s.voxel_keys.resize(high_water_);
  s.voxel_counts.resize(high_water_);
  s.points.resize(high_water_ * n);
  s.covs.resize(high_water_ * n);
  const cudaStream_t st = executor_->stream();
  voxel_keys_.download(s.voxel_keys.data(), high_water_, st);
  voxel_counts_.download(s.voxel_counts.data(), high_water_, st);
  points_.download(s.points.data(), high_water_ * n, st);
  covs_.download(s.covs.data(), high_water_ * n, st);
  return s;
}

KnnResults DeviceVoxelMap::knn(const std::vector<Eigen::Vector3f>& queries, int k, float max_distance2) const {
  if (k <= 0 || k > map::kMaxNeighbors) throw std::invalid_argument("knn: k must be in [1, kMaxNeighbors]");
  const std::size_t nq = queries.size();
  const auto per = static_cast<std::size_t>(k);
  KnnResults r;
  r.k = k;
  r.found.resize(nq);
  r.indices.resize(nq * per);
  r.distances2.resize(nq * per);
  if (nq == 0) return r;
  DeviceBuffer<Eigen::Vector3f> q(nq, "queries");
  DeviceBuffer<int> found(nq, "queries");
  DeviceBuffer<std::int64_t> idx(nq * per, "queries");
  DeviceBuffer<float> d2(nq * per, "queries");
  const cudaStream_t st = executor_->stream();
  q.upload(queries.data(), nq, st, "(queries)");
  constexpr int kAllOnes = 0xFF;  // index -1, distance NaN: the ranks no neighbour fills
  FARLIO_CUDA_CHECK(cudaMemsetAsync(idx.data(), kAllOnes, idx.bytes(), st));
  FARLIO_CUDA_CHECK(cudaMemsetAsync(d2.data(), kAllOnes, d2.bytes(), st));
  const map::ConstMapView v = view();
  const Eigen::Vector3f* qp = q.data();
  int* fp = found.data();
  std::int64_t* ip = idx.data();
  float* dp = d2.data();
  executor_->for_each(nq, [=] __device__(std::size_t i) {
    fp[i] = map::knn_search(v, qp[i], k, max_distance2, ip + i * per, dp + i * per);
  });
  found.download(r.found.data(), nq, st);
  idx.download(r.indices.data(), nq * per, st);
  d2.download(r.distances2.data(), nq * per, st);
  return r;
}

}  // namespace farlio::cuda
