#pragma once
// The voxel hash map's flat layout (the paper's cuVoxelMap), seen through raw pointers so that
// the same kernel bodies run on the host (CpuExecutor) and on the device (CUDA). The memory is
// owned by map::VoxelMap (host) or cuda::DeviceVoxelMap (device); updates go through a MapView,
// searches and the registration read through a ConstMapView.
//
// Table: open addressing with linear probing (step 1) over `table_capacity` slots (a power of
// two); slot_keys[s] is a packed voxel key, kEmptyKey or kErasedKey; slot_voxels[s] is the
// voxel's index in the pool. Pool: voxel v holds voxel_counts[v] points at
// points[v * max_points_per_voxel + j]; point.w() is its PointShape (covariance.hpp): 0 without
// a valid covariance in covs[...].
#include <Eigen/Core>
#include <cstdint>
#include <type_traits>

#include "farlio/exec/atomics.hpp"
#include "farlio/exec/hd.hpp"
#include "farlio/map/covariance.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::map {

/// kMutable: the kernels may write through the view (map updates); else it only reads.
template <bool kMutable>
struct BasicMapView {
  template <typename T>
  using Ptr = std::conditional_t<kMutable, T*, const T*>;

  Ptr<std::uint64_t> slot_keys = nullptr;
  Ptr<std::int32_t> slot_voxels = nullptr;
  std::uint64_t table_capacity = 0;  // power of two
  Ptr<std::uint64_t> voxel_keys = nullptr;
  Ptr<std::int32_t> voxel_counts = nullptr;
  Ptr<Eigen::Vector4f> points = nullptr;
  Ptr<Cov3> covs = nullptr;
  std::int32_t max_points_per_voxel = 0;
  float voxel_size = 1.0f;
  float inv_voxel_size = 1.0f;

  FARLIO_HD std::int64_t point_index(std::int32_t voxel, std::int32_t j) const {
    return static_cast<std::int64_t>(voxel) * max_points_per_voxel + j;
  }

  /// A mutable view reads as a read-only one (written <!kMutable> so that the read-only view
  /// declares no conversion to its own type).
  FARLIO_HD operator BasicMapView<!kMutable>() const requires kMutable {
    return {slot_keys, slot_voxels, table_capacity,       voxel_keys, voxel_counts,
            points,    covs,        max_points_per_voxel, voxel_size, inv_voxel_size};
  }
};

using MapView = BasicMapView<true>;
using ConstMapView = BasicMapView<false>;

/// The view of an owner's table and pool buffers (VoxelMap's vectors, DeviceVoxelMap's device
/// buffers) laid out for `max_points_per_voxel` points in voxels of `voxel_size_m`.
template <typename View>
View make_map_view(typename View::template Ptr<std::uint64_t> slot_keys,
                   typename View::template Ptr<std::int32_t> slot_voxels, std::uint64_t table_capacity,
                   typename View::template Ptr<std::uint64_t> voxel_keys,
                   typename View::template Ptr<std::int32_t> voxel_counts,
                   typename View::template Ptr<Eigen::Vector4f> points, typename View::template Ptr<Cov3> covs,
                   std::int32_t max_points_per_voxel, double voxel_size_m) {
  return {slot_keys,
          slot_voxels,
          table_capacity,
          voxel_keys,
          voxel_counts,
          points,
          covs,
          max_points_per_voxel,
          static_cast<float>(voxel_size_m),
          static_cast<float>(1.0 / voxel_size_m)};
}

/// Voxel index stored under `key`, or -1. Probes at most table_capacity slots.
FARLIO_HD inline std::int32_t table_find(const ConstMapView& m, std::uint64_t key, std::uint64_t hash) {
  const std::uint64_t mask = m.table_capacity - 1;
  for (std::uint64_t i = 0, s = hash & mask; i < m.table_capacity; ++i, s = (s + 1) & mask) {
    const std::uint64_t k = exec::atomic_load(&m.slot_keys[s]);
    if (k == key) return m.slot_voxels[s];
    if (k == kEmptyKey) return -1;
  }
  return -1;
}

FARLIO_HD inline std::int32_t table_find(const ConstMapView& m, const VoxelCoord& c) {
  return table_find(m, pack_key(c), spatial_hash(c));
}

/// Inserts key -> voxel if the key is absent (thread-safe; erased slots are not reused here,
/// the owner rehashes when they pile up). Returns the slot, or -1 when the table is full.
FARLIO_HD inline std::int64_t table_insert(const MapView& m, std::uint64_t key, std::uint64_t hash,
                                           std::int32_t voxel) {
  const std::uint64_t mask = m.table_capacity - 1;
  for (std::uint64_t i = 0, s = hash & mask; i < m.table_capacity; ++i, s = (s + 1) & mask) {
    const std::uint64_t prev = exec::atomic_cas(&m.slot_keys[s], kEmptyKey, key);
    if (prev == kEmptyKey) {
      m.slot_voxels[s] = voxel;
      return static_cast<std::int64_t>(s);
    }
    if (prev == key) return static_cast<std::int64_t>(s);
  }
  return -1;
}

/// Replaces `key` by the erased marker; returns false if absent.
FARLIO_HD inline bool table_erase(const MapView& m, std::uint64_t key, std::uint64_t hash) {
  const std::uint64_t mask = m.table_capacity - 1;
  for (std::uint64_t i = 0, s = hash & mask; i < m.table_capacity; ++i, s = (s + 1) & mask) {
    const std::uint64_t k = m.slot_keys[s];
    if (k == key) {
      m.slot_keys[s] = kErasedKey;
      return true;
    }
    if (k == kEmptyKey) return false;
  }
  return false;
}

}  // namespace farlio::map
