// CellDownsampler against a brute-force reference: the lowest index of each cell, in key order,
// for scans ordered as a LiDAR delivers them, shuffled, with dropped points, with every point
// in its own cell (the table must grow), and repeated calls (the reused table must be clean).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/voxel_key.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/preprocess/cell_downsampler.hpp"

using namespace farlio;

namespace {

std::vector<std::int32_t> reference(const std::vector<std::uint64_t>& keys) {
  std::map<std::uint64_t, std::int32_t> first;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] != map::kEmptyKey) first.try_emplace(keys[i], static_cast<std::int32_t>(i));
  }
  std::vector<std::int32_t> out;
  for (const auto& [key, index] : first) out.push_back(index);
  return out;
}

/// Keys of a ring scan (azimuth-ordered, as a spinning LiDAR delivers it) at cell size `cell_m`.
std::vector<std::uint64_t> ring_scan_keys(float cell_m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> range(2.0f, 60.0f), drop(0.0f, 1.0f);
  constexpr int kBeams = 32, kColumns = 2000;
  std::vector<std::uint64_t> keys;
  for (int b = 0; b < kBeams; ++b) {
    const float elevation = -0.4f + 0.02f * static_cast<float>(b);
    for (int c = 0; c < kColumns; ++c) {
      const float az = 6.2831853f * static_cast<float>(c) / kColumns, r = range(rng);
      const Eigen::Vector3f p(r * std::cos(az), r * std::sin(az), r * elevation);
      keys.push_back(drop(rng) < 0.05f ? map::kEmptyKey : map::point_key(p, 1.0f / cell_m));
    }
  }
  return keys;
}

class CellDownsamplerTest : public ::testing::TestWithParam<int> {};

TEST_P(CellDownsamplerTest, EqualsTheLowestIndexOfEachCellInKeyOrder) {
  exec::CpuExecutor ex(GetParam());
  preprocess::CellDownsampler d;
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    auto keys = ring_scan_keys(0.63f, seed);
    EXPECT_EQ(d.first_of_each_cell(keys.data(), keys.size(), ex), reference(keys)) << "ordered, seed " << seed;
    std::shuffle(keys.begin(), keys.end(), std::mt19937(seed));
    EXPECT_EQ(d.first_of_each_cell(keys.data(), keys.size(), ex), reference(keys)) << "shuffled, seed " << seed;
  }
}

TEST_P(CellDownsamplerTest, GrowsWhenEveryPointHasItsOwnCellAndShrinksBackCorrectly) {
  exec::CpuExecutor ex(GetParam());
  preprocess::CellDownsampler d;
  const auto coarse = ring_scan_keys(4.0f, 7);  // few cells: a small table
  EXPECT_EQ(d.first_of_each_cell(coarse.data(), coarse.size(), ex), reference(coarse));
  std::vector<std::uint64_t> distinct;  // 64k cells, far more than the table was sized for
  for (int i = 0; i < 65536; ++i) distinct.push_back(map::pack_key({i % 41, i / 41, -i % 7}));
  const auto& kept = d.first_of_each_cell(distinct.data(), distinct.size(), ex);
  EXPECT_EQ(kept, reference(distinct));
  EXPECT_EQ(kept.size(), 65536u);
  EXPECT_EQ(d.first_of_each_cell(coarse.data(), coarse.size(), ex), reference(coarse));
  const std::vector<std::uint64_t> none(100, map::kEmptyKey);
  EXPECT_TRUE(d.first_of_each_cell(none.data(), none.size(), ex).empty());
  EXPECT_TRUE(d.first_of_each_cell(nullptr, 0, ex).empty());
}

INSTANTIATE_TEST_SUITE_P(Threads, CellDownsamplerTest, ::testing::Values(1, 2, 4));

}  // namespace
