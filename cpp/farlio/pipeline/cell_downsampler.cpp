#include "farlio/pipeline/cell_downsampler.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>

#include "farlio/map/voxel_key.hpp"

namespace farlio::pipeline {
namespace {

constexpr std::size_t kMinSlots = std::size_t{1} << 10;
/// Slots per expected cell (the previous scan's count): the table starts a quarter full.
constexpr std::size_t kSlotsPerExpectedCell = 4;
}  // namespace

void CellTable::reset(std::size_t expected_cells) {
  const std::size_t slots = std::bit_ceil(std::max(kMinSlots, kSlotsPerExpectedCell * expected_cells));
  if (keys_.size() != slots) {
    keys_.assign(slots, map::kEmptyKey);
    first_.assign(slots, 0);
  }
  cells_ = 0;
}

void CellTable::insert_min(std::uint64_t key, std::int32_t index) {
  const std::size_t mask = keys_.size() - 1;
  std::size_t s = map::packed_key_slot(key, mask);
  while (keys_[s] != key && keys_[s] != map::kEmptyKey) s = (s + 1) & mask;
  if (keys_[s] == key) {
    first_[s] = std::min(first_[s], index);
    return;
  }
  keys_[s] = key;
  first_[s] = index;
  if (2 * ++cells_ > keys_.size()) grow();
}

void CellTable::grow() {
  std::vector<std::pair<std::uint64_t, std::int32_t>> held;
  held.reserve(cells_);
  drain(held);
  keys_.assign(2 * keys_.size(), map::kEmptyKey);
  first_.assign(keys_.size(), 0);
  for (const auto& [key, index] : held) insert_min(key, index);
}

void CellTable::drain(std::vector<std::pair<std::uint64_t, std::int32_t>>& out) {
  for (std::size_t s = 0; s < keys_.size(); ++s) {
    if (keys_[s] == map::kEmptyKey) continue;
    out.emplace_back(keys_[s], first_[s]);
    keys_[s] = map::kEmptyKey;
  }
  cells_ = 0;
}

const std::vector<std::int32_t>& CellDownsampler::first_of_each_cell(const std::uint64_t* keys, std::size_t n,
                                                                     exec::CpuExecutor& executor) {
  const auto blocks = static_cast<std::size_t>(std::max(1, executor.num_threads()));
  tables_.resize(blocks);
  // 1. each block of the scan into its own table (a task per block, one thread each)
  executor.for_each(
      blocks,
      [&](std::size_t b) {
        CellTable& table = tables_[b];
        table.reset(expected_cells_);
        std::uint64_t previous = map::kEmptyKey;
        for (std::size_t i = b * n / blocks; i < (b + 1) * n / blocks; ++i) {
          const std::uint64_t key = keys[i];
          // the previous point of the block had the same cell and a lower index: nothing to do
          if (key == map::kEmptyKey || key == previous) continue;
          previous = key;
          table.insert_min(key, static_cast<std::int32_t>(i));
        }
      },
      1);
  // 2. merge the blocks' tables into the first (lowest index per cell), then its cells in key order
  for (std::size_t b = 1; b < blocks; ++b) {
    cells_.clear();
    tables_[b].drain(cells_);
    for (const auto& [key, index] : cells_) tables_[0].insert_min(key, index);
  }
  cells_.clear();
  tables_[0].drain(cells_);
  executor.run([&] { tbb::parallel_sort(cells_.begin(), cells_.end()); });
  kept_.resize(cells_.size());
  for (std::size_t c = 0; c < cells_.size(); ++c) kept_[c] = cells_[c].second;
  expected_cells_ = cells_.size();
  return kept_;
}

}  // namespace farlio::pipeline
