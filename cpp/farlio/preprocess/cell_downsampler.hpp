#pragma once
// Downsampling to one point per cell: the first point (lowest index) of each cell, found with
// hash tables of the cells on the CPU executor instead of a sort of all points. A scan of ~120k
// points falls into ~10k cells of the map spacing; sorting the points by cell cost more than all
// the other preprocessing (docs/performance.md). Each thread deduplicates its block of the scan
// (every n-th chunk of 4096 points) into its own table (no atomics, no cache line shared between
// cores), skipping a point whose neighbour in the scan order fell into the same cell, and sorts
// its cells by key; the blocks' sorted cells are then merged and the first of each cell kept.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::preprocess {

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

  /// The same with the keys computed in the blocks' loop: keys_of(first, count, out) writes the
  /// keys of points [first, first + count) to out (count <= 64), once per point.
  template <typename KeysOf>
  const std::vector<std::int32_t>& first_of_each_cell(std::size_t n, exec::CpuExecutor& executor,
                                                      const KeysOf& keys_of) {
    const auto blocks = static_cast<std::size_t>(std::max(1, executor.num_threads()));
    blocks_.resize(blocks);
    // each block into its own table, its cells then sorted by key (a task per block, one
    // thread each). Block b takes the chunks b, b + blocks, b + 2 blocks, ... of the scan: parts
    // of a scan differ in cost (far rings put each point in a new cell), and contiguous halves
    // would leave one thread waiting for the other (KITTI: 757 against 457 us)
    const std::size_t chunks = (n + kChunkPoints - 1) / kChunkPoints;
    executor.for_each(
        blocks,
        [&](std::size_t b) {
          Block& block = blocks_[b];
          block.table.reset(expected_cells_);
          // a key in `recent` is in the table with a lower index of this block: nothing to do
          std::array<std::uint64_t, kRecentCells> recent;
          recent.fill(map::kEmptyKey);
          std::uint64_t keys[kKeyBatch];
          for (std::size_t chunk = b; chunk < chunks; chunk += blocks) {
            // the bounds in locals: computed in the loop's condition, they cost a division per
            // point (the table's stores might alias what they are computed from)
            const std::size_t begin = chunk * kChunkPoints, end = std::min(n, begin + kChunkPoints);
            for (std::size_t i0 = begin; i0 < end; i0 += kKeyBatch) {
              const std::size_t len = std::min(kKeyBatch, end - i0);
              keys_of(i0, len, keys);
              for (std::size_t j = 0; j < len; ++j) {
                const std::uint64_t key = keys[j];
                if (key == map::kEmptyKey) continue;
                std::uint64_t& slot = recent[map::packed_key_slot(key, kRecentCells - 1)];
                if (slot == key) continue;
                slot = key;
                block.table.insert_min(key, static_cast<std::int32_t>(i0 + j));
              }
            }
          }
          block.sort_cells();
        },
        1);
    return merge_blocks(blocks);
  }

 private:
  /// Entries of a block's filter of recently inserted cells (direct-mapped, 4 KiB: stays in L1).
  /// A scan visits a cell again within a few dozen points (the next column of a spinning LiDAR,
  /// the next point of a ring), so most repeats are caught there instead of by a table probe.
  static constexpr std::size_t kRecentCells = 512;
  /// Points whose keys are computed in one loop before they are looked up.
  static constexpr std::size_t kKeyBatch = 64;
  /// Points of a chunk of the scan: the blocks take the chunks in turn.
  static constexpr std::size_t kChunkPoints = 4096;

  /// One block of the scan: its cells and their lowest indices, then the same sorted by key.
  struct Block {
    CellTable table;
    std::vector<std::pair<std::uint64_t, std::int32_t>> cells, scratch;
    /// Drains the table into `cells`, sorted by key (each key once: the table holds it once).
    void sort_cells();
  };

  /// The blocks' cells merged in key order, the lowest index of a cell found in several blocks
  /// kept: their indices.
  const std::vector<std::int32_t>& merge_blocks(std::size_t blocks);

  std::vector<Block> blocks_;  // one per block of the scan (a block per thread)
  std::array<std::vector<std::pair<std::uint64_t, std::int32_t>>, 2> merged_;  // the merges before the last
  std::vector<std::int32_t> kept_;
  std::size_t expected_cells_ = 0;  // cells of the previous call: sizes the tables
};

}  // namespace farlio::preprocess
