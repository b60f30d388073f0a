#pragma once
// Grouping of points by a key (their voxel), groups in key order and the points of a group in
// input order: what a sort of (key, index) pairs gives, found with a hash table of the distinct
// keys, a sort of those alone (hundreds of voxels, not thousands of points) and a stable
// counting scatter. The map updates group their candidates this way (voxel_map.cpp).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace farlio::map {

class KeyGrouping {
 public:
  /// Groups the indices i in [0, n) with keys[i] != kEmptyKey; returns the number of groups.
  std::size_t group(const std::uint64_t* keys, std::size_t n);

  /// Key of group g (ascending in g).
  [[nodiscard]] std::uint64_t key(std::size_t g) const { return group_keys_[g]; }
  /// The members of group g are order()[start(g)] .. order()[start(g + 1) - 1].
  [[nodiscard]] std::size_t start(std::size_t g) const { return group_start_[g]; }
  [[nodiscard]] const std::vector<std::int32_t>& order() const { return order_; }
  /// Indices with kEmptyKey (left out of every group).
  [[nodiscard]] std::size_t dropped() const { return dropped_; }

 private:
  std::vector<std::uint64_t> slot_keys_;
  std::vector<std::int32_t> slot_group_;
  // scratch kept across calls (no allocation once grown)
  std::vector<std::uint64_t> first_seen_;  // distinct keys in order of first appearance
  std::vector<std::size_t> counts_;        // members of each, same order
  std::vector<std::int32_t> by_key_;       // first-appearance numbers sorted by key
  std::vector<std::size_t> cursor_;
  std::vector<std::int32_t> member_group_;  // first-appearance number of each index
  std::vector<std::uint64_t> group_keys_;
  std::vector<std::int32_t> rank_;  // table-order group -> key-order group
  std::vector<std::size_t> group_start_;
  std::vector<std::int32_t> order_;
  std::size_t dropped_ = 0;
};

}  // namespace farlio::map
