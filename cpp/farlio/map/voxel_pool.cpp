#include "farlio/map/voxel_pool.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "farlio/core/error.hpp"

namespace farlio::map {
namespace {
constexpr std::size_t kMinTableSlots = 16;

[[noreturn]] void throw_full(std::size_t needed, const std::string& parameter, std::size_t capacity) {
  throw CapacityError("voxel map is full: " + std::to_string(needed) + " voxels needed, " + parameter + " is " +
                      std::to_string(capacity) + "; raise it or lower map.removal_radius_m");
}
}  // namespace

std::size_t table_capacity_for(std::size_t voxel_capacity) {
  return std::bit_ceil(std::max(kMinTableSlots, kSlotsPerVoxel * voxel_capacity));
}

std::size_t voxels_needed(const PoolCounts& counts, std::size_t new_voxels) {
  return counts.high_water + (new_voxels - std::min(new_voxels, counts.free_voxels));
}

InsertionPlan plan_insertion(const PoolCounts& counts, std::size_t new_voxels, std::size_t voxel_capacity,
                             const std::string& capacity_parameter) {
  InsertionPlan plan;
  plan.from_free_list = std::min(new_voxels, counts.free_voxels);
  plan.high_water = voxels_needed(counts, new_voxels);
  if (plan.high_water > voxel_capacity) throw_full(plan.high_water, capacity_parameter, voxel_capacity);
  const std::size_t slots = std::max(counts.table_slots, table_capacity_for(voxel_capacity));
  const bool too_full =
      static_cast<double>(counts.used_slots + new_voxels) > static_cast<double>(counts.table_slots) / kSlotsPerVoxel;
  if (slots > counts.table_slots || too_full) plan.rehash_slots = slots;
  return plan;
}

std::size_t grown_pool_capacity(std::size_t needed, std::size_t capacity, std::size_t limit,
                                const std::string& limit_parameter) {
  if (needed <= capacity) return capacity;
  if (needed > limit) throw_full(needed, limit_parameter, limit);
  return std::min(limit, std::max(needed, 2 * capacity));
}

bool rehash_after_removal(const PoolCounts& counts) {
  return static_cast<double>(counts.used_slots - counts.live_voxels) >
         kMaxErasedFraction * static_cast<double>(counts.table_slots);
}

bool removal_applies(const VoxelMapConfig& config, std::size_t high_water) {
  return high_water > 0 && std::isfinite(config.removal_radius_m);
}

}  // namespace farlio::map
