// KeyGrouping against the sort it replaces: (key, index) pairs sorted, kEmptyKey dropped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "farlio/map/key_grouping.hpp"
#include "farlio/map/voxel_key.hpp"

using namespace farlio;

namespace {

void expect_equals_the_sort(map::KeyGrouping& g, const std::vector<std::uint64_t>& keys) {
  std::vector<std::pair<std::uint64_t, std::int32_t>> sorted;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] != map::kEmptyKey) sorted.emplace_back(keys[i], static_cast<std::int32_t>(i));
  }
  std::sort(sorted.begin(), sorted.end());
  const std::size_t groups = g.group(keys.data(), keys.size());
  ASSERT_EQ(g.order().size(), sorted.size());
  EXPECT_EQ(g.dropped(), keys.size() - sorted.size());
  std::size_t expected_groups = 0;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    EXPECT_EQ(g.order()[i], sorted[i].second) << i;
    if (i == 0 || sorted[i].first != sorted[i - 1].first) {
      ASSERT_LT(expected_groups, groups);
      EXPECT_EQ(g.start(expected_groups), i);
      EXPECT_EQ(g.key(expected_groups), sorted[i].first);
      ++expected_groups;
    }
  }
  EXPECT_EQ(groups, expected_groups);
  EXPECT_EQ(g.start(groups), sorted.size());
}

TEST(KeyGrouping, EqualsSortingTheKeyIndexPairs) {
  map::KeyGrouping g;  // reused across calls, as the maps do
  std::mt19937 rng(4);
  for (int distinct : {1, 7, 700, 20000}) {
    std::uniform_int_distribution<int> cell(-distinct / 2, distinct / 2);
    std::vector<std::uint64_t> keys;
    for (int i = 0; i < 20000; ++i) {
      keys.push_back(i % 97 == 0 ? map::kEmptyKey : map::pack_key({cell(rng), cell(rng) % 3, 0}));
    }
    expect_equals_the_sort(g, keys);
  }
  // runs of one key, as points in the order of their downsampling cells give, with a key
  // coming back after other runs
  std::vector<std::uint64_t> runs;
  std::uniform_int_distribution<int> run_length(1, 12), run_key(0, 40);
  while (runs.size() < 20000) {
    const std::uint64_t key = run_key(rng) == 0 ? map::kEmptyKey : map::pack_key({run_key(rng), 1, 2});
    runs.insert(runs.end(), static_cast<std::size_t>(run_length(rng)), key);
  }
  expect_equals_the_sort(g, runs);
  expect_equals_the_sort(g, {});
  expect_equals_the_sort(g, std::vector<std::uint64_t>(50, map::kEmptyKey));
}

}  // namespace
