#include "farlio/map/key_grouping.hpp"

#include <algorithm>
#include <bit>
#include <numeric>

#include "farlio/map/voxel_key.hpp"

namespace farlio::map {
namespace {

constexpr std::size_t kMinSlots = 1024;
constexpr std::size_t kSlotsPerIndex = 2;  // at most half full even when every key differs

}  // namespace

std::size_t KeyGrouping::group(const std::uint64_t* keys, std::size_t n) {
  const std::size_t slots = std::bit_ceil(std::max(kMinSlots, kSlotsPerIndex * n));
  if (slot_keys_.size() != slots) {
    slot_keys_.assign(slots, kEmptyKey);
    slot_group_.assign(slots, -1);
  }
  const std::size_t mask = slots - 1;
  // 1. the distinct keys (groups numbered in order of first appearance) and each index's group
  first_seen_.clear();
  counts_.clear();
  member_group_.resize(n);
  dropped_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t key = keys[i];
    if (key == kEmptyKey) {
      member_group_[i] = -1;
      ++dropped_;
      continue;
    }
    std::size_t s = packed_key_slot(key, mask);
    while (slot_keys_[s] != key && slot_keys_[s] != kEmptyKey) s = (s + 1) & mask;
    if (slot_keys_[s] == kEmptyKey) {
      slot_keys_[s] = key;
      slot_group_[s] = static_cast<std::int32_t>(first_seen_.size());
      first_seen_.push_back(key);
      counts_.push_back(0);
    }
    member_group_[i] = slot_group_[s];
    ++counts_[static_cast<std::size_t>(slot_group_[s])];
  }
  // 2. groups ranked by key; the table emptied for the next call (only the slots used)
  const std::size_t groups = first_seen_.size();
  by_key_.resize(groups);
  std::iota(by_key_.begin(), by_key_.end(), 0);
  std::sort(by_key_.begin(), by_key_.end(), [&](std::int32_t a, std::int32_t b) {
    return first_seen_[static_cast<std::size_t>(a)] < first_seen_[static_cast<std::size_t>(b)];
  });
  rank_.resize(groups);
  group_keys_.resize(groups);
  group_start_.assign(groups + 1, 0);
  for (std::size_t r = 0; r < groups; ++r) {
    const auto g = static_cast<std::size_t>(by_key_[r]);
    rank_[g] = static_cast<std::int32_t>(r);
    group_keys_[r] = first_seen_[g];
    group_start_[r + 1] = group_start_[r] + counts_[g];
  }
  for (const std::uint64_t key : first_seen_) {
    std::size_t s = packed_key_slot(key, mask);
    while (slot_keys_[s] != key) s = (s + 1) & mask;
    slot_keys_[s] = kEmptyKey;
  }
  // 3. stable scatter: input order inside each group
  order_.resize(n - dropped_);
  cursor_.assign(group_start_.begin(), group_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    if (member_group_[i] < 0) continue;
    const auto r = static_cast<std::size_t>(rank_[static_cast<std::size_t>(member_group_[i])]);
    order_[cursor_[r]++] = static_cast<std::int32_t>(i);
  }
  return groups;
}

}  // namespace farlio::map
