#pragma once
// The work arrays of one update (a map insertion, a removal, a downsampling), shared by the
// maps of one backend since its stages run one after the other on one stream. Sized once for
// the largest input: max(scan points, map voxels) + 1.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "farlio/cuda/cuda_executor.hpp"
#include "farlio/cuda/device_algorithms.hpp"
#include "farlio/cuda/device_buffer.hpp"
#include "farlio/cuda/read_back.hpp"
#include "farlio/map/key_window.hpp"
#include "farlio/map/voxel_update.hpp"

namespace farlio::cuda {

struct MapScratch {
  explicit MapScratch(std::size_t items, CudaExecutor& executor);

  std::size_t items;
  DeviceBuffer<std::uint64_t> keys, sorted_keys;
  DeviceBuffer<std::uint64_t> short_keys;       ///< keys shortened to a KeyWindow (sort_into_groups)
  DeviceBuffer<std::int32_t> iota;              ///< 0, 1, 2, ... (filled once)
  DeviceBuffer<std::int32_t> sorted_order;      ///< input index of each sorted key
  DeviceBuffer<Eigen::Vector3f> sorted_points;  ///< an insertion's candidates in sorted order
  DeviceBuffer<std::uint8_t> flags;
  DeviceBuffer<std::int32_t> group_start;  ///< sorted position of each group's first key, then the end
  DeviceBuffer<std::int32_t> group_voxel, missing, rank, first_new;
  DeviceBuffer<map::GroupStats> group_stats;
  DeviceBuffer<std::int32_t> scalars;  ///< small device-side results (positions below)

  [[nodiscard]] std::size_t memory_bytes() const;
};

/// Positions of scalars.
inline constexpr int kScalarFirstEmpty = 0;     ///< sorted position of the first kEmptyKey (or n)
inline constexpr int kScalarTableFull = 1;      ///< failed table insertions
inline constexpr int kScalarOutsideWindow = 2;  ///< a key fell outside sort_into_groups' window
inline constexpr int kScalarGroups = 3;         ///< groups of the last sort_into_groups
inline constexpr int kScalarCount = 4;

/// The groups that sort_into_groups found.
struct SortedGroups {
  std::size_t groups = 0;
  std::size_t valid = 0;  ///< keys that are not kEmptyKey
};

/// Work queued after the sort, before the one wait for its counts: kernels over the upper bound
/// n that read the group count on the device (scalars[kScalarGroups]), and the copies of what the
/// caller needs back, posted to the read-back. It runs again if the keys are sorted a second time.
using AfterSort = std::function<void(ReadBack&)>;

/// Sorts scratch.keys[0, n) with their indices (order: key, then index) and finds the groups of
/// equal keys, kEmptyKey excluded: group g starts at sorted position group_start[g] and ends at
/// group_start[g + 1] (written too). sorted_keys holds the sorted full keys. The host waits once,
/// for the counts and for whatever `after_sort` posted to executor.read_back(). With a usable
/// `window` (the box the keys are expected in) the sort compares the keys' short form
/// (map/key_window.hpp: fewer radix passes, the same order); if a key falls outside it, the keys
/// are sorted again in full.
SortedGroups sort_into_groups(MapScratch& scratch, CudaExecutor& executor, DeviceAlgorithms& algorithms, std::size_t n,
                              const map::KeyWindow& window = {}, const AfterSort& after_sort = {});

}  // namespace farlio::cuda
