// KeyWindow, the short keys the CUDA backend sorts: for points within the radius they are inside
// the box, they order as the full keys do (a stable sort by short key equals one by full key),
// they expand back to the key, and a key outside the box is reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "farlio/map/key_window.hpp"
#include "farlio/map/voxel_update.hpp"

using namespace farlio;

namespace {

struct Case {
  Eigen::Vector3d centre;
  double radius_m;
  double cell_m;
};

// sensor-frame scans (centre 0) and world-frame map updates far from the origin, negative too
const Case kCases[] = {
    {{0.0, 0.0, 0.0}, 200.0, 0.5},          // preprocessing: default crop, map spacing
    {{0.0, 0.0, 0.0}, 110.0, 1.0},          // frame map
    {{-2345.6, 812.3, -41.7}, 110.0, 1.0},  // map update far from the origin
    {{15000.2, -9000.9, 3.3}, 60.0, 0.25},  // a fine grid
    {{0.3, -0.2, 0.1}, 0.0, 1.0},           // a point
};

/// Points within radius of centre (on the sphere too), as floats, their keys, and some empties.
std::vector<std::uint64_t> keys_within(const Case& c, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> dir(0.0, 1.0);
  std::uniform_real_distribution<double> radius(0.0, 1.0);
  std::vector<std::uint64_t> keys;
  const auto inv = static_cast<float>(1.0 / c.cell_m);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 17 == 0) {
      keys.push_back(map::kEmptyKey);
      continue;
    }
    Eigen::Vector3d d(dir(rng), dir(rng), dir(rng));
    d.normalize();
    const double r = i % 5 == 0 ? c.radius_m : c.radius_m * std::cbrt(radius(rng));
    keys.push_back(map::point_key((c.centre + r * d).cast<float>(), inv));
  }
  return keys;
}

}  // namespace

TEST(KeyWindow, ShortKeysOrderAsTheKeysAndExpandBack) {
  for (const Case& c : kCases) {
    const auto w = map::KeyWindow::around(c.centre, c.radius_m, 1.0 / c.cell_m);
    ASSERT_TRUE(w.usable());
    EXPECT_LE(w.total_bits(), map::KeyWindow::kMaxBits);
    const auto keys = keys_within(c, 20000, 7);
    std::vector<std::uint64_t> shorter(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
      bool outside = false;
      shorter[i] = w.shorten(keys[i], &outside);
      ASSERT_FALSE(outside) << "key " << i << " of a point within the radius";
      EXPECT_EQ(w.expand(shorter[i]), keys[i]);
      EXPECT_LT(shorter[i], std::uint64_t{1} << w.total_bits());
      EXPECT_EQ(shorter[i] == w.empty_short_key(), keys[i] == map::kEmptyKey);
    }
    // a stable sort by short key gives the stable sort by key: the same order and groups
    std::vector<std::int32_t> by_key(keys.size()), by_short(keys.size());
    std::iota(by_key.begin(), by_key.end(), 0);
    std::iota(by_short.begin(), by_short.end(), 0);
    std::stable_sort(by_key.begin(), by_key.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
    std::stable_sort(by_short.begin(), by_short.end(), [&](auto a, auto b) { return shorter[a] < shorter[b]; });
    EXPECT_EQ(by_key, by_short);
  }
}

TEST(KeyWindow, SavesRadixPassesForAScan) {
  // the default crop (200 m) at the default spacing and voxel sizes: about half the 64 bits
  const auto scan = map::KeyWindow::around(Eigen::Vector3d::Zero(), 200.0, 1.0 / 0.5);
  EXPECT_LE(scan.total_bits(), 30);
  const auto map_update = map::KeyWindow::around(Eigen::Vector3d(1e4, -3e3, 20.0), 210.0, 1.0);
  EXPECT_LE(map_update.total_bits(), 27);
}

TEST(KeyWindow, AKeyOutsideTheBoxIsReported) {
  const auto w = map::KeyWindow::around(Eigen::Vector3d(10.0, -5.0, 2.0), 20.0, 1.0);
  ASSERT_TRUE(w.usable());
  // the box is [-11, 31] x [-26, 16] x [-19, 23] cells, rounded up to 64 cells per axis
  const std::vector<Eigen::Vector3i> outside_cells = {
      {100, 0, 0}, {10, -80, 2}, {10, -5, 100}, {-60, -5, 2}, {1000000, 0, 0}};
  for (const auto& c : outside_cells) {
    bool outside = false;
    (void)w.shorten(map::pack_key(c), &outside);
    EXPECT_TRUE(outside) << c.transpose();
  }
  bool outside = false;
  (void)w.shorten(map::pack_key({10, -5, 2}), &outside);
  EXPECT_FALSE(outside);
}

TEST(KeyWindow, NoWindowWithoutAFiniteRadiusOrBeyondTheKeyRange) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(map::KeyWindow::around(Eigen::Vector3d::Zero(), inf, 1.0).usable());
  EXPECT_FALSE(map::KeyWindow::around(Eigen::Vector3d::Zero(), std::nan(""), 1.0).usable());
  EXPECT_FALSE(map::KeyWindow::around(Eigen::Vector3d::Zero(), 100.0, 0.0).usable());
  EXPECT_FALSE(map::KeyWindow::around(Eigen::Vector3d(5e6, 0.0, 0.0), 100.0, 1.0).usable());  // beyond 2^20 cells
  EXPECT_FALSE(map::KeyWindow::around(Eigen::Vector3d::Zero(), 1e5, 100.0).usable());         // over kMaxBits
}
