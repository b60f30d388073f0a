#pragma once
// The decisions of a map update that both owners of the voxel hash map take, the host VoxelMap
// and the CUDA backend's DeviceVoxelMap, written once: how large the pool must grow, when the
// table is rehashed, which pool slots new voxels take, and whether removal applies. The owners
// only carry them out on their own memory (a growing std::vector, or device buffers allocated
// once), so that they keep the same contents in the same pool slots.
#include <cstddef>
#include <cstdint>
#include <string>

#include "farlio/core/config.hpp"
#include "farlio/exec/hd.hpp"

namespace farlio::map {

/// The table keeps at least this many slots per voxel of pool capacity (load factor <= 0.5).
inline constexpr std::size_t kSlotsPerVoxel = 2;
/// Rehash (in place) when erased markers exceed this fraction of the table.
inline constexpr double kMaxErasedFraction = 0.25;

/// Slots of the table for a pool of `voxel_capacity` voxels (a power of two).
std::size_t table_capacity_for(std::size_t voxel_capacity);

/// The counters of a pool and its table.
struct PoolCounts {
  std::size_t high_water = 0;   ///< voxels [0, high_water) have been used at least once
  std::size_t free_voxels = 0;  ///< removed voxels below the high-water mark, reused first
  std::size_t live_voxels = 0;
  std::size_t used_slots = 0;  ///< table slots holding a key or an erased marker
  std::size_t table_slots = 0;
};

/// What inserting `new_voxels` voxels that are not in the map yet takes.
struct InsertionPlan {
  std::size_t from_free_list = 0;  ///< how many reuse removed voxels (from the back of the list)
  std::size_t high_water = 0;      ///< the high-water mark after the insertion
  std::size_t rehash_slots = 0;    ///< rehash to this many slots first; 0: the table takes them as it is
};

/// The pool slots an insertion of `new_voxels` new voxels uses up to (its high-water mark after).
std::size_t voxels_needed(const PoolCounts& counts, std::size_t new_voxels);

/// Decides an insertion of `new_voxels` new voxels into a pool of `voxel_capacity` voxels (a
/// host pool grows before it, so pass the grown capacity). The table is rehashed when it would
/// be more than half full, erased slots counted: in place, unless the live voxels alone need a
/// larger one. Throws CapacityError naming `capacity_parameter` when the pool cannot hold them.
InsertionPlan plan_insertion(const PoolCounts& counts, std::size_t new_voxels, std::size_t voxel_capacity,
                             const std::string& capacity_parameter);

/// The pool capacity a host pool of `capacity` voxels grows to so that it holds `needed`:
/// doubling, at most `limit`. Throws CapacityError naming `limit_parameter` beyond the limit.
std::size_t grown_pool_capacity(std::size_t needed, std::size_t capacity, std::size_t limit,
                                const std::string& limit_parameter);

/// Whether a removal left so many erased markers that the table is to be rehashed in place.
bool rehash_after_removal(const PoolCounts& counts);

/// Whether remove_far can remove anything: a finite radius and a used pool.
bool removal_applies(const VoxelMapConfig& config, std::size_t high_water);

/// The pool slot of the new voxel of rank `rank` (0, 1, ... in key order): removed voxels from
/// the back of the free list first, then the slots from the high-water mark on.
FARLIO_HD inline std::int32_t new_voxel_slot(std::int32_t rank, const std::int32_t* free_list, std::size_t free_count,
                                             std::size_t from_free_list, std::size_t high_water) {
  const auto reused = static_cast<std::int32_t>(from_free_list);
  if (rank < reused) return free_list[static_cast<std::int64_t>(free_count) - 1 - rank];
  return static_cast<std::int32_t>(high_water) + (rank - reused);
}

}  // namespace farlio::map
