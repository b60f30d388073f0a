#include "farlio/pipeline/cell_downsampler.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <limits>

#include "farlio/exec/atomics.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::pipeline {
namespace {

constexpr std::size_t kMinSlots = std::size_t{1} << 12;
/// Slots per cell expected (the previous scan's count): the table is a quarter full, and it is
/// abandoned for one kGrowth times larger when a scan fills it beyond half.
constexpr std::size_t kSlotsPerExpectedCell = 4;
constexpr std::size_t kGrowth = 4;
constexpr std::int32_t kNoIndex = std::numeric_limits<std::int32_t>::max();
/// Fibonacci hashing of a packed key (its bits are three axis coordinates side by side).
constexpr std::uint64_t kHashMultiplier = 0x9E3779B97F4A7C15ULL;

std::size_t slot_of(std::uint64_t key, std::size_t mask) {
  return static_cast<std::size_t>((key * kHashMultiplier) >> 20) & mask;
}

void atomic_min(std::int32_t* addr, std::int32_t v) {
  std::atomic_ref<std::int32_t> a(*addr);
  std::int32_t cur = a.load(std::memory_order_relaxed);
  while (v < cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
}

}  // namespace

bool CellDownsampler::fill_table(const std::uint64_t* keys, std::size_t n, std::size_t slots,
                                 exec::CpuExecutor& executor) {
  if (slot_keys_.size() != slots) {
    slot_keys_.assign(slots, map::kEmptyKey);
    slot_first_.assign(slots, kNoIndex);
  }
  const std::size_t mask = slots - 1, max_cells = slots / 2;
  std::atomic<std::size_t> cells{0};
  std::atomic<bool> full{false};
  executor.for_each_range(n, [&](std::size_t begin, std::size_t end) {
    std::uint64_t previous = map::kEmptyKey;
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint64_t key = keys[i];
      // the previous point of this range had the same cell and a lower index: nothing to do
      if (key == map::kEmptyKey || key == previous) continue;
      previous = key;
      std::size_t s = slot_of(key, mask);
      for (;;) {
        // a plain load finds a cell already there without a locked instruction
        std::uint64_t found = exec::atomic_load(&slot_keys_[s]);
        if (found == map::kEmptyKey) found = exec::atomic_cas(&slot_keys_[s], map::kEmptyKey, key);
        if (found == map::kEmptyKey && cells.fetch_add(1, std::memory_order_relaxed) + 1 > max_cells) {
          full.store(true, std::memory_order_relaxed);
        }
        if (found == map::kEmptyKey || found == key) break;
        s = (s + 1) & mask;
      }
      atomic_min(&slot_first_[s], static_cast<std::int32_t>(i));
      if (full.load(std::memory_order_relaxed)) return;  // at most one more cell per thread
    }
  });
  return !full.load();
}

void CellDownsampler::drain_table() {
  cells_.clear();
  for (std::size_t s = 0; s < slot_keys_.size(); ++s) {
    if (slot_keys_[s] == map::kEmptyKey) continue;
    cells_.emplace_back(slot_keys_[s], slot_first_[s]);
    slot_keys_[s] = map::kEmptyKey;
    slot_first_[s] = kNoIndex;
  }
}

const std::vector<std::int32_t>& CellDownsampler::first_of_each_cell(const std::uint64_t* keys, std::size_t n,
                                                                     exec::CpuExecutor& executor) {
  std::size_t slots = std::bit_ceil(std::max(kMinSlots, kSlotsPerExpectedCell * expected_cells_));
  while (!fill_table(keys, n, slots, executor)) {
    drain_table();
    slots *= kGrowth;
  }
  drain_table();
  executor.run([&] { tbb::parallel_sort(cells_.begin(), cells_.end()); });
  kept_.resize(cells_.size());
  for (std::size_t c = 0; c < cells_.size(); ++c) kept_[c] = cells_[c].second;
  expected_cells_ = cells_.size();
  return kept_;
}

}  // namespace farlio::pipeline
