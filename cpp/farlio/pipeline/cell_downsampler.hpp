#pragma once
// Downsampling to one point per cell: the first point (lowest index) of each cell, found with
// hash tables of the cells on the CPU executor instead of a sort of all points. A scan of ~120k
// points falls into ~10k cells of the map spacing; sorting the points by cell cost more than all
// the other preprocessing (docs/performance.md). Each thread deduplicates a contiguous block of
// the scan into its own table (no atomics, no cache line shared between cores), skipping a point
// whose neighbour in the scan order fell into the same cell; the blocks' cells are then sorted
// together by key and the first of each cell kept.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::pipeline {

/// An open-addressing table cell key -> lowest index seen, owned by one thread at a time.
class CellTable {
 public:
  /// Empties the table and gives it room for about `expected_cells` cells.
  void reset(std::size_t expected_cells);
  /// Records `index` for `key` (keeps the lowest); grows when half full.
  void insert_min(std::uint64_t key, std::int32_t index);
  /// Appends every (key, lowest index) to `out` (in the order the cells arrived) and empties the
  /// table, visiting only the slots in use.
  void drain(std::vector<std::pair<std::uint64_t, std::int32_t>>& out);

 private:
  void grow();

  std::vector<std::uint64_t> keys_;
  std::vector<std::int32_t> first_;
  std::vector<std::uint32_t> used_;  // the slots holding a cell, in insertion order
};

class CellDownsampler {
 public:
  /// keys[i] is the cell key of point i (map::point_key; kEmptyKey for a dropped point).
  /// Returns the index of the first point of each cell, in key order: the same as sorting the
  /// (key, index) pairs and keeping the first pair of each key. Valid until the next call.
  const std::vector<std::int32_t>& first_of_each_cell(const std::uint64_t* keys, std::size_t n,
                                                      exec::CpuExecutor& executor);

  /// The same with the keys computed in the blocks' loop: key_of(i) is the key of point i, called
  /// once per point (the preprocessing's per-point body, which also writes the point).
  template <typename KeyOf>
  const std::vector<std::int32_t>& first_of_each_cell(std::size_t n, exec::CpuExecutor& executor, const KeyOf& key_of) {
    const auto blocks = static_cast<std::size_t>(std::max(1, executor.num_threads()));
    tables_.resize(blocks);
    // each block of the scan into its own table (a task per block, one thread each)
    executor.for_each(
        blocks,
        [&](std::size_t b) {
          CellTable& table = tables_[b];
          table.reset(expected_cells_);
          // a key in `recent` is in the table with a lower index of this block: nothing to do
          std::array<std::uint64_t, kRecentCells> recent;
          recent.fill(map::kEmptyKey);
          for (std::size_t i = b * n / blocks; i < (b + 1) * n / blocks; ++i) {
            const std::uint64_t key = key_of(i);
            if (key == map::kEmptyKey) continue;
            std::uint64_t& slot = recent[map::packed_key_slot(key, kRecentCells - 1)];
            if (slot == key) continue;
            slot = key;
            table.insert_min(key, static_cast<std::int32_t>(i));
          }
        },
        1);
    return merge_blocks(blocks);
  }

 private:
  /// Entries of a block's filter of recently inserted cells (direct-mapped, 4 KiB: stays in L1).
  /// A scan visits a cell again within a few dozen points (the next column of a spinning LiDAR,
  /// the next point of a ring), so most repeats are caught there instead of by a table probe.
  static constexpr std::size_t kRecentCells = 512;

  /// The blocks' cells (lowest index per cell) in key order: their indices.
  const std::vector<std::int32_t>& merge_blocks(std::size_t blocks);

  std::vector<CellTable> tables_;  // one per block of the scan (a block per thread)
  std::vector<std::pair<std::uint64_t, std::int32_t>> cells_, scratch_;
  std::vector<std::int32_t> kept_;
  std::size_t expected_cells_ = 0;  // cells of the previous call: sizes the tables
};

}  // namespace farlio::pipeline
