#include "farlio/preprocess/cell_downsampler.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <utility>

#include "farlio/map/voxel_key.hpp"

namespace farlio::preprocess {
namespace {

constexpr std::size_t kMinSlots = std::size_t{1} << 10;
/// Slots per expected cell (the previous scan's count): the table starts a quarter full.
constexpr std::size_t kSlotsPerExpectedCell = 4;
constexpr int kDigitBits = 8;
constexpr std::size_t kDigitValues = std::size_t{1} << kDigitBits;
constexpr int kKeyBits = 64;

/// Sorts `cells` by key, stably (least-significant-digit radix sort, 8 bits a pass; a pass whose
/// digit is the same in every key is skipped: cells of one scan share the high bits of each
/// coordinate). The order equals std::stable_sort's. `scratch` is kept between calls.
void radix_sort_by_key(std::vector<std::pair<std::uint64_t, std::int32_t>>& cells,
                       std::vector<std::pair<std::uint64_t, std::int32_t>>& scratch) {
  scratch.resize(cells.size());
  for (int shift = 0; shift < kKeyBits; shift += kDigitBits) {
    std::array<std::size_t, kDigitValues> count{};
    for (const auto& c : cells) ++count[(c.first >> shift) & (kDigitValues - 1)];
    if (std::find(count.begin(), count.end(), cells.size()) != count.end()) continue;  // one digit value
    std::size_t offset = 0;
    for (std::size_t& n : count) offset += std::exchange(n, offset);
    for (const auto& c : cells) scratch[count[(c.first >> shift) & (kDigitValues - 1)]++] = c;
    cells.swap(scratch);
  }
}

/// Merges two lists of cells sorted by key (each key once in each) in key order: out(key, index)
/// per cell, a cell in both once with the lower index. Two cursors and no branch on the keys,
/// whose order alternates between the lists at random.
template <typename Out>
void merge_cells(const std::vector<std::pair<std::uint64_t, std::int32_t>>& a,
                 const std::vector<std::pair<std::uint64_t, std::int32_t>>& b, const Out& out) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const std::uint64_t ka = a[i].first, kb = b[j].first;
    const std::int32_t ia = a[i].second, ib = b[j].second;
    const bool take_a = ka <= kb, take_b = kb <= ka;  // both: the same cell, its lower index kept
    out(take_a ? ka : kb, take_a ? (take_b ? std::min(ia, ib) : ia) : ib);
    i += take_a ? 1 : 0;
    j += take_b ? 1 : 0;
  }
  for (; i < a.size(); ++i) out(a[i].first, a[i].second);
  for (; j < b.size(); ++j) out(b[j].first, b[j].second);
}
}  // namespace

void CellTable::reset(std::size_t expected_cells) {
  const std::size_t slots = std::bit_ceil(std::max(kMinSlots, kSlotsPerExpectedCell * expected_cells));
  if (keys_.size() != slots) {
    keys_.assign(slots, map::kEmptyKey);
    first_.assign(slots, 0);
    used_.clear();
  }
  for (const std::uint32_t s : used_) keys_[s] = map::kEmptyKey;  // a table not drained since
  used_.clear();
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
  used_.push_back(static_cast<std::uint32_t>(s));
  if (2 * used_.size() > keys_.size()) grow();
}

void CellTable::grow() {
  std::vector<std::pair<std::uint64_t, std::int32_t>> held;
  held.reserve(used_.size());
  drain(held);
  keys_.assign(2 * keys_.size(), map::kEmptyKey);
  first_.assign(keys_.size(), 0);
  for (const auto& [key, index] : held) insert_min(key, index);
}

void CellTable::drain(std::vector<std::pair<std::uint64_t, std::int32_t>>& out) {
  // only the slots in use: the table has several empty slots per cell
  for (const std::uint32_t s : used_) {
    out.emplace_back(keys_[s], first_[s]);
    keys_[s] = map::kEmptyKey;
  }
  used_.clear();
}

const std::vector<std::int32_t>& CellDownsampler::first_of_each_cell(const std::uint64_t* keys, std::size_t n,
                                                                     exec::CpuExecutor& executor) {
  return first_of_each_cell(n, executor, [keys](std::size_t first, std::size_t count, std::uint64_t* out) {
    std::copy(keys + first, keys + first + count, out);
  });
}

void CellDownsampler::Block::sort_cells() {
  cells.clear();
  table.drain(cells);
  radix_sort_by_key(cells, scratch);
}

const std::vector<std::int32_t>& CellDownsampler::merge_blocks(std::size_t blocks) {
  // 2. the blocks' sorted cells merged by key, two lists at a time (a cell in several blocks
  // keeps its lowest index); the last merge writes the indices
  kept_.clear();
  const std::vector<std::pair<std::uint64_t, std::int32_t>>* merged = &blocks_[0].cells;
  for (std::size_t b = 1; b + 1 < blocks; ++b) {
    auto& next = merged_[b % 2];  // not the list `merged` points to (merged_[(b - 1) % 2] or a block's)
    next.clear();
    merge_cells(*merged, blocks_[b].cells,
                [&](std::uint64_t key, std::int32_t index) { next.emplace_back(key, index); });
    merged = &next;
  }
  if (blocks == 1) {
    for (const auto& cell : *merged) kept_.push_back(cell.second);
  } else {
    kept_.reserve(merged->size() + blocks_[blocks - 1].cells.size());
    merge_cells(*merged, blocks_[blocks - 1].cells, [&](std::uint64_t, std::int32_t index) { kept_.push_back(index); });
  }
  expected_cells_ = kept_.size();
  return kept_;
}

}  // namespace farlio::preprocess
