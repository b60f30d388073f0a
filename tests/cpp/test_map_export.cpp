// The whole-map export (pipeline/map_export.hpp) against a brute-force voxel centroid.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include "farlio/map/voxel_key.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/map_export.hpp"
#include "scene_fixture.hpp"

using namespace farlio;

namespace {

constexpr double kResolution_m = 0.5;

SE3 sensor_pose() {
  Vec6d xi;
  xi << 3.0, -2.0, 1.5, 0.02, -0.01, 0.7;
  return SE3::exp(xi);
}

/// The scene sampled in the world, seen from `pose` (sensor frame), with intensity `intensity`.
Scan scan_from(const SE3& pose, unsigned seed, float intensity) {
  Scan s;
  const SE3 inv = pose.inverse();
  for (const auto& p : test::sample_scene(20000, seed, 0.0f)) {
    s.points.push_back((inv * p.cast<double>()).cast<float>());
    s.intensity.push_back(intensity);
  }
  return s;
}

struct Centroid {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double intensity = 0;
  int count = 0;
};

}  // namespace

TEST(MapExport, EqualsTheBruteForceCentroidOfEveryCell) {
  const PreprocessConfig crop;  // 1..200 m
  pipeline::MapExport e(kResolution_m, crop);
  const SE3 pose = sensor_pose();
  const Scan scan = scan_from(pose, 7, 0.0f);
  const std::size_t added = e.add(scan, deskew::ScanMotion{}, false, pose);

  std::map<std::uint64_t, Centroid> brute;
  std::size_t kept = 0;
  for (const auto& p : scan.points) {
    const double r = p.cast<double>().norm();
    if (r < crop.min_range_m || r > crop.max_range_m) continue;
    const Eigen::Vector3d w = pose * p.cast<double>();
    Centroid& c = brute[map::point_key(w.cast<float>(), static_cast<float>(1.0 / kResolution_m))];
    c.sum += w;
    ++c.count;
    ++kept;
  }
  EXPECT_EQ(added, kept);
  EXPECT_EQ(e.points_added(), kept);
  ASSERT_EQ(e.cells(), brute.size());
  const Scan out = e.points();
  ASSERT_EQ(out.size(), brute.size());
  std::size_t i = 0;
  for (const auto& [key, c] : brute) {  // both in key order
    EXPECT_LT((out.points[i].cast<double>() - c.sum / c.count).norm(), 1e-4) << "cell " << i;
    // the centroid lies in its cell (up to rounding: the floor lies on cell faces)
    const Eigen::Vector3d corner = map::unpack_key(key).cast<double>() * kResolution_m;
    const Eigen::Vector3d local = out.points[i].cast<double>() - corner;
    EXPECT_TRUE((local.array() > -1e-4).all() && (local.array() < kResolution_m + 1e-4).all()) << "cell " << i;
    ++i;
  }
}

TEST(MapExport, ARevisitAddsNoCellAndAveragesIntensity) {
  pipeline::MapExport e(kResolution_m, PreprocessConfig{});
  const SE3 pose = sensor_pose();
  e.add(scan_from(pose, 7, 10.0f), deskew::ScanMotion{}, false, pose);
  const std::size_t cells = e.cells();
  const std::size_t bytes = e.memory_bytes();
  const Scan first = e.points();
  // the same points again (a second lap) with another intensity
  e.add(scan_from(pose, 7, 30.0f), deskew::ScanMotion{}, false, pose);
  EXPECT_EQ(e.cells(), cells);
  EXPECT_EQ(e.memory_bytes(), bytes);
  const Scan second = e.points();
  ASSERT_EQ(second.size(), first.size());
  for (std::size_t i = 0; i < second.size(); ++i) {
    EXPECT_LT((second.points[i] - first.points[i]).norm(), 1e-4);
    EXPECT_FLOAT_EQ(second.intensity[i], 20.0f);
  }
}

TEST(MapExport, FarFromTheOriginKeepsMillimetres) {
  // 5 km away: the sums are kept relative to the cell, so float does not lose the points
  pipeline::MapExport e(0.1, PreprocessConfig{});
  const SE3 pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(5000.0, -4000.0, 120.0));
  Scan s;
  s.points = {{10.03f, 2.01f, 0.52f}, {10.07f, 2.04f, 0.55f}};
  e.add(s, deskew::ScanMotion{}, false, pose);
  const Scan out = e.points();
  ASSERT_EQ(out.size(), 1u);
  const Eigen::Vector3d expected = pose * Eigen::Vector3d(10.05, 2.025, 0.535);
  EXPECT_LT((out.points[0].cast<double>() - expected).norm(), 2e-3);
  EXPECT_TRUE(out.intensity.size() == 1 && out.intensity[0] == 0.0f);  // no intensity in the scan
}

TEST(MapExport, CroppedAndNonFinitePointsAreLeftOut) {
  pipeline::MapExport e(kResolution_m, PreprocessConfig{});
  Scan s;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  s.points = {{0.2f, 0.0f, 0.0f}, {500.0f, 0.0f, 0.0f}, {nan, 1.0f, 1.0f}, {5.0f, 0.0f, 0.0f}};
  EXPECT_EQ(e.add(s, deskew::ScanMotion{}, false, SE3()), 1u);
  EXPECT_EQ(e.cells(), 1u);
}

TEST(MapExport, RejectsAResolutionOutOfRange) {
  EXPECT_THROW(pipeline::MapExport(0.0, PreprocessConfig{}), std::invalid_argument);
  EXPECT_THROW(pipeline::MapExport(std::nan(""), PreprocessConfig{}), std::invalid_argument);
}

TEST(MapExport, ExportResolutionDefaultsToThePointSpacing) {
  Config c;
  c.map.voxel_size_m = 4.0;
  c.map.max_points_per_voxel = 16;
  EXPECT_DOUBLE_EQ(pipeline::export_resolution_m(c), 1.0);
  c.map.export_resolution_m = 0.2;
  EXPECT_DOUBLE_EQ(pipeline::export_resolution_m(c), 0.2);
}

namespace {

/// The scene around a sensor (sensor frame): what every pose below sees of its own surroundings.
Scan local_scan() {
  Scan s;
  for (const auto& p : test::sample_scene(20000, 11, 0.0f)) {
    s.points.push_back(p);
    s.intensity.push_back(p.z());
  }
  return s;
}

/// The points of a map as a sorted list of (x, y, z, intensity).
std::vector<std::array<float, 4>> sorted_points(const Scan& s) {
  std::vector<std::array<float, 4>> out;
  for (std::size_t i = 0; i < s.size(); ++i)
    out.push_back({s.points[i].x(), s.points[i].y(), s.points[i].z(), s.intensity[i]});
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(MapExport, TilesLeftBehindWaitOnDiskAndComeBack) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "farlio_test_map_tiles";
  std::filesystem::remove_all(dir);
  PreprocessConfig crop;
  crop.max_range_m = 20.0;  // a tile of 10 m is within reach up to 28.7 m, spilled beyond 38.7 m
  const Scan scan = local_scan();
  const auto at = [](double x) { return SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, 0.0, 0.0)); };
  {
    pipeline::MapExport spilling(kResolution_m, crop, 0, dir, 10.0);
    pipeline::MapExport all(kResolution_m, crop);
    for (const double x : {0.0, 100.0, 200.0}) {
      spilling.add(scan, deskew::ScanMotion{}, false, at(x));
      all.add(scan, deskew::ScanMotion{}, false, at(x));
    }
    EXPECT_EQ(spilling.cells(), all.cells());
    EXPECT_GT(spilling.tiles_on_disk(), 0u);
    EXPECT_LT(spilling.cells_in_memory(), spilling.cells() / 2);  // two of the three places are on disk
    EXPECT_LT(spilling.memory_bytes(), all.memory_bytes());
    EXPECT_FALSE(std::filesystem::is_empty(dir));
    // back at the start: its tiles come back before the points are added, and the revisit adds no cell
    const std::size_t cells = spilling.cells();
    spilling.add(scan, deskew::ScanMotion{}, false, at(0.0));
    all.add(scan, deskew::ScanMotion{}, false, at(0.0));
    EXPECT_EQ(spilling.cells(), cells);
    // the same map either way: every cell once, with the same sums
    EXPECT_EQ(sorted_points(spilling.points()), sorted_points(all.points()));
    std::size_t streamed = 0;
    spilling.for_each_piece([&](std::span<const Vec3f> p, std::span<const float> i) {
      EXPECT_EQ(p.size(), i.size());
      streamed += p.size();
    });
    EXPECT_EQ(streamed, cells);
  }
  EXPECT_FALSE(std::filesystem::exists(dir));  // the tiles' files and the folder are removed
}
