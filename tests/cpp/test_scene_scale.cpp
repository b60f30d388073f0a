// The map's scale chosen at the first scan (preprocess::scene_voxel_size_m): the range rule keeps
// the paper's 4 m outdoors, and a scan that fills too few voxels at that size (a narrow field of
// view, a close wall) gets a finer voxel until it fills map.auto_min_voxels of them. Scans are ray
// cast in a box room and on an open ground plane, so the answer follows from the geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/preprocess/preprocess.hpp"

using namespace farlio;

namespace {

/// Where a ray from the origin along `d` leaves the box [lo, hi] (the origin inside it).
Eigen::Vector3f exit_point(const Eigen::Vector3d& d, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t = 1e9;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 1e-12) t = std::min(t, hi[a] / d[a]);
    if (d[a] < -1e-12) t = std::min(t, lo[a] / d[a]);
  }
  return (t * d).cast<float>();
}

/// A scan of `n` rays in a room 10 m x 6 m x 3 m around the sensor, uniform over the sphere or,
/// narrow, within a forward cone of a Livox Avia's size (70 x 77 degrees) looking along +x.
std::vector<Eigen::Vector3f> room_scan(bool narrow, std::size_t n, unsigned seed) {
  const Eigen::Vector3d lo(-4.0, -3.0, -1.2), hi(6.0, 3.0, 1.8);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3f> points;
  while (points.size() < n) {
    const Eigen::Vector3d d = Eigen::Vector3d(u(rng), u(rng), u(rng));
    if (d.norm() > 1.0 || d.norm() < 1e-3) continue;  // uniform directions: inside the unit ball
    const Eigen::Vector3d dir = d.normalized();
    const double azimuth = std::atan2(dir.y(), dir.x()), elevation = std::asin(dir.z());
    if (narrow &&
        (std::abs(azimuth) > 35.0 * std::numbers::pi / 180.0 || std::abs(elevation) > 38.5 * std::numbers::pi / 180.0))
      continue;
    points.push_back(exit_point(dir, lo, hi));
  }
  return points;
}

/// An open scene: ground 1.8 m below a spinning sensor, out to 80 m, with a few building walls.
std::vector<Eigen::Vector3f> outdoor_scan(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi), range(3.0, 80.0),
      height(-1.8, 8.0);
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = angle(rng);
    if (i % 2 == 0) {  // the ground
      const double r = range(rng);
      points.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)), -1.8f);
    } else {  // facades 25-60 m away
      const double r = 25.0 + 35.0 * std::abs(std::sin(3.0 * a));
      points.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                          static_cast<float>(height(rng)));
    }
  }
  return points;
}

/// Distinct voxels by a set of integer coordinates (in float, as the map computes them: a point on a
/// voxel's face belongs where the map puts it).
std::size_t brute_force_voxels(const std::vector<Eigen::Vector3f>& points, double voxel_m) {
  const auto inv = static_cast<float>(1.0 / voxel_m);
  std::set<std::tuple<long, long, long>> keys;
  for (const auto& p : points) {
    keys.emplace(std::lround(std::floor(p.x() * inv)), std::lround(std::floor(p.y() * inv)),
                 std::lround(std::floor(p.z() * inv)));
  }
  return keys.size();
}

}  // namespace

TEST(SceneScale, OccupiedVoxelsAreABruteForceCount) {
  const auto points = room_scan(false, 5000, 1);
  for (double voxel : {0.3, 0.7, 1.3, 4.0}) {
    const std::size_t all = brute_force_voxels(points, voxel);
    EXPECT_EQ(preprocess::occupied_voxels(points, voxel, points.size()), all) << voxel;
    // the count stops at `enough`, and counts them all when there are fewer
    EXPECT_EQ(preprocess::occupied_voxels(points, voxel, points.size(), all / 2), all / 2) << voxel;
    EXPECT_EQ(preprocess::occupied_voxels(points, voxel, points.size(), all + 1), all) << voxel;
  }
}

TEST(SceneScale, ANarrowViewOfARoomGetsAFinerVoxelThatFillsEnoughOfThem) {
  const VoxelMapConfig config;
  const auto sphere = room_scan(false, 20000, 2), cone = room_scan(true, 20000, 3);
  const double v_sphere = preprocess::scene_voxel_size_m(sphere, config);
  const double v_cone = preprocess::scene_voxel_size_m(cone, config);
  const auto filled = [](const std::vector<Eigen::Vector3f>& p, double v) {
    return preprocess::occupied_voxels(p, v, p.size());
  };
  // the whole room fills enough voxels at the range rule's size; the cone does not, and shrinks
  VoxelMapConfig range_rule = config;
  range_rule.auto_min_voxels = 0;
  EXPECT_DOUBLE_EQ(v_sphere, preprocess::scene_voxel_size_m(sphere, range_rule));
  const double v_cone_range_rule = preprocess::scene_voxel_size_m(cone, range_rule);
  EXPECT_LT(filled(cone, v_cone_range_rule), static_cast<std::size_t>(config.auto_min_voxels));
  EXPECT_LT(v_cone, 0.9 * v_cone_range_rule);
  EXPECT_GE(v_cone, config.auto_min_voxel_size_m);
  EXPECT_GE(filled(cone, v_cone), static_cast<std::size_t>(config.auto_min_voxels));
  EXPECT_GE(filled(sphere, v_sphere), static_cast<std::size_t>(config.auto_min_voxels));
}

TEST(SceneScale, TheVoxelStopsAtTheSmallestAutoSize) {
  VoxelMapConfig config;
  config.auto_min_voxels = 1000000;  // more than any scan here fills
  EXPECT_DOUBLE_EQ(preprocess::scene_voxel_size_m(room_scan(true, 5000, 4), config), config.auto_min_voxel_size_m);
}

TEST(SceneScale, OutdoorsKeepsThePapersVoxel) {
  const VoxelMapConfig config;
  EXPECT_DOUBLE_EQ(preprocess::scene_voxel_size_m(outdoor_scan(30000, 5), config), config.voxel_size_m);
}

TEST(SceneScale, AFixedVoxelIsKept) {
  VoxelMapConfig config;
  config.auto_voxel_size = false;
  config.voxel_size_m = 2.5;
  EXPECT_DOUBLE_EQ(preprocess::scene_voxel_size_m(room_scan(true, 5000, 6), config), 2.5);
}
