#pragma once
// Downsampling to one point per cell: the first point (lowest index) of each cell, found with
// a hash table of the cells on the CPU executor instead of a sort of all points. A scan of
// ~120k points falls into ~10k cells of the map spacing; sorting the points by cell cost more
// than all the other preprocessing (docs/performance.md), while one probe of a table that
// stays in cache per point, skipped when the point's neighbour in the scan order fell into the
// same cell, is close to the cost of reading the keys.
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"

namespace farlio::pipeline {

class CellDownsampler {
 public:
  /// keys[i] is the cell key of point i (map::point_key; kEmptyKey for a dropped point).
  /// Returns the index of the first point of each cell, in key order: the same as sorting the
  /// (key, index) pairs and keeping the first pair of each key. Valid until the next call.
  const std::vector<std::int32_t>& first_of_each_cell(const std::uint64_t* keys, std::size_t n,
                                                      exec::CpuExecutor& executor);

 private:
  /// Inserts the keys into a table of `slots` slots; false when it filled beyond half (the
  /// table is then cleared and the caller retries with a larger one).
  bool fill_table(const std::uint64_t* keys, std::size_t n, std::size_t slots, exec::CpuExecutor& executor);
  /// Moves the table's cells into cells_ and empties the table.
  void drain_table();

  std::vector<std::uint64_t> slot_keys_;
  std::vector<std::int32_t> slot_first_;
  std::vector<std::pair<std::uint64_t, std::int32_t>> cells_;
  std::vector<std::int32_t> kept_;
  std::size_t expected_cells_ = 0;  // cells of the previous call: sizes the table
};

}  // namespace farlio::pipeline
