// The device voxel map against the host VoxelMap on the same points: the same voxels, the same
// points in the same pool slots, covariances equal to float rounding (and their line/surface
// shape but for rare flips at the threshold), the same k-NN results.
#include <gtest/gtest.h>

#include <cmath>

#include "cuda_test_support.hpp"
#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/key_window.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "scene_fixture.hpp"

using namespace farlio;

namespace {

constexpr std::size_t kScenePoints = 120000;
constexpr std::size_t kVoxelCapacity = 1 << 16;
// Covariances: Eigen may vectorise the host's Frobenius norm (another summation order).
constexpr float kCovRelTol = 1e-4f;
// Line/surface classification (closed-form eigenvalues: acosf, cosf of libdevice vs glibc) may
// flip for a covariance right at map.line_eigenvalue_ratio.
constexpr double kMaxShapeFlipFraction = 1e-3;

std::vector<Eigen::Vector3f> shifted(std::vector<Eigen::Vector3f> pts, const Eigen::Vector3f& d) {
  for (auto& p : pts) p += d;
  return pts;
}

/// The same voxels, and the same points in the same pool slots; with `covariances`, also the
/// same covariances (to float rounding) and shapes (but for rare flips).
void expect_same_maps(const map::MapSnapshot& cpu, const map::MapSnapshot& gpu, bool covariances = true) {
  ASSERT_EQ(cpu.voxel_keys, gpu.voxel_keys);
  ASSERT_EQ(cpu.voxel_counts, gpu.voxel_counts);
  const auto n = static_cast<std::size_t>(cpu.max_points_per_voxel);
  std::size_t compared = 0, flips = 0;
  for (std::size_t v = 0; v < cpu.voxel_keys.size(); ++v) {
    for (std::size_t j = 0; j < static_cast<std::size_t>(cpu.voxel_counts[v]); ++j, ++compared) {
      const std::size_t i = v * n + j;
      ASSERT_EQ(cpu.points[i].head<3>(), gpu.points[i].head<3>()) << "voxel " << v << " point " << j;
      if (!covariances) continue;
      ASSERT_EQ(map::has_covariance(cpu.points[i]), map::has_covariance(gpu.points[i]))
          << "voxel " << v << " point " << j;
      flips += map::is_line_like(cpu.points[i]) != map::is_line_like(gpu.points[i]) ? 1 : 0;
      if (!map::has_covariance(cpu.points[i])) continue;
      const Eigen::Matrix3f a = cpu.covs[i].matrix(), b = gpu.covs[i].matrix();
      ASSERT_LE((a - b).norm(), kCovRelTol * a.norm()) << "voxel " << v << " point " << j;
    }
  }
  EXPECT_GT(compared, 1000u);
  EXPECT_LE(static_cast<double>(flips), kMaxShapeFlipFraction * static_cast<double>(compared));
}

/// A limit that decays with the distance (the adaptive density's shape).
const map::PointLimit kDecayingLimit{30, 10.0f, 0.5f, 10};

/// A host map and a device map with 2 m voxels that removal empties beyond 30 m.
struct RemovalMaps {
  static VoxelMapConfig config() {
    VoxelMapConfig cfg;
    cfg.voxel_size_m = 2.0;
    cfg.removal_radius_m = 30.0;
    return cfg;
  }
  exec::CpuExecutor executor{2};
  map::VoxelMap cpu{config(), executor};
  test::DeviceMapRig gpu{config(), kVoxelCapacity};
};

}  // namespace

TEST(CudaMap, InsertionRemovalAndCovariancesEqualTheCpu) {
  FARLIO_REQUIRE_GPU();
  RemovalMaps maps;
  map::VoxelMap& cpu = maps.cpu;
  test::DeviceMapRig& gpu = maps.gpu;
  const map::PointLimit& asmd = kDecayingLimit;
  const auto a = test::sample_scene(kScenePoints, 11, 0.02f);
  const auto b = shifted(test::sample_scene(kScenePoints, 12, 0.02f), {20.0f, 3.0f, 0.0f});
  const auto sa = cpu.insert(a, Eigen::Vector3f::Zero(), asmd);
  const auto ga = gpu.insert(a, Eigen::Vector3f::Zero(), asmd);
  EXPECT_EQ(sa.inserted, ga.inserted);
  EXPECT_EQ(sa.rejected_spacing, ga.rejected_spacing);
  EXPECT_EQ(sa.rejected_full, ga.rejected_full);
  EXPECT_EQ(sa.new_voxels, ga.new_voxels);
  EXPECT_EQ(sa.covariances_computed, ga.covariances_computed);
  // removal frees voxels, the next insertion reuses them in the same order
  const Eigen::Vector3f far_origin(40.0f, 0.0f, 0.0f);
  EXPECT_EQ(cpu.remove_far(far_origin), gpu.map.remove_far(far_origin));
  EXPECT_EQ(cpu.insert(b, far_origin, asmd).inserted, gpu.insert(b, far_origin, asmd).inserted);
  EXPECT_EQ(cpu.num_voxels(), gpu.map.num_voxels());
  EXPECT_EQ(cpu.num_points(), gpu.map.num_points());
  EXPECT_DOUBLE_EQ(cpu.mean_points_per_voxel(far_origin, 20.0), gpu.map.mean_points_per_voxel(far_origin, 20.0));
  expect_same_maps(cpu.snapshot(), gpu.map.snapshot());
}

TEST(CudaMap, KnnEqualsTheCpu) {
  FARLIO_REQUIRE_GPU();
  const VoxelMapConfig cfg;
  exec::CpuExecutor ex(2);
  map::VoxelMap cpu(cfg, ex);
  test::DeviceMapRig gpu(cfg, kVoxelCapacity);
  const auto pts = test::sample_scene(kScenePoints, 21, 0.02f);
  cpu.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  gpu.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  const auto queries = test::sample_scene(5000, 22, 0.3f);
  constexpr int kK = 10;
  constexpr float kMaxD2 = 4.0f;
  const cuda::KnnResults r = gpu.map.knn(queries, kK, kMaxD2);
  const map::MapView v = cpu.view();
  for (std::size_t q = 0; q < queries.size(); ++q) {
    std::int64_t idx[kK];
    float d2[kK];
    const int found = map::knn_search(v, queries[q], kK, kMaxD2, idx, d2);
    ASSERT_EQ(found, r.found[q]) << "query " << q;
    for (int j = 0; j < found; ++j) {
      EXPECT_EQ(idx[j], r.indices[q * kK + static_cast<std::size_t>(j)]) << "query " << q << " rank " << j;
      EXPECT_EQ(d2[j], r.distances2[q * kK + static_cast<std::size_t>(j)]) << "query " << q << " rank " << j;
    }
  }
}

TEST(CudaMap, AFullMapIsACapacityErrorNamingTheParameter) {
  FARLIO_REQUIRE_GPU();
  constexpr std::size_t kTinyCapacity = 8;
  test::DeviceMapRig gpu(VoxelMapConfig{}, kTinyCapacity);
  try {
    gpu.insert(test::sample_scene(10000, 3), Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
    FAIL() << "expected CapacityError";
  } catch (const CapacityError& e) {
    EXPECT_NE(std::string(e.what()).find("test voxel capacity"), std::string::npos) << e.what();
  }
}

TEST(CudaMap, LoadMapEqualsTheCpu) {
  // a prior map (farlio localize): one piece when it fits the scan buffers, else several
  FARLIO_REQUIRE_GPU();
  const auto pts = test::sample_scene(kScenePoints, 31, 0.02f);
  Config cpu_config;
  cpu_config.device = Device::Cpu;
  pipeline::ScanPipeline cpu(cpu_config);
  cpu.backend().load_map(pts);
  Config gpu_config;
  gpu_config.device = Device::Cuda;
  pipeline::ScanPipeline gpu(gpu_config);
  ASSERT_GE(static_cast<std::size_t>(gpu_config.cuda.max_scan_points), pts.size());
  gpu.backend().load_map(pts);
  expect_same_maps(cpu.backend().map_snapshot(), gpu.backend().map_snapshot());
  // in pieces of 50k points: the same points (a covariance computed before a later piece filled
  // a neighbouring voxel may differ from the one-piece map's, so only the points are compared)
  constexpr std::int64_t kPiecePoints = 50000;
  gpu_config.cuda.max_scan_points = kPiecePoints;
  pipeline::ScanPipeline pieces(gpu_config);
  pieces.backend().load_map(pts);
  expect_same_maps(cpu.backend().map_snapshot(), pieces.backend().map_snapshot(), false);
}

TEST(CudaMap, SortsOnShortKeysOrFallBackToTheFullKeysWithTheSameMap) {
  // the voxel sort on short keys (points said to lie within a radius), narrow or wide, and its
  // fallback when some do not: the map must equal the CPU's either way
  FARLIO_REQUIRE_GPU();
  VoxelMapConfig cfg;
  cfg.voxel_size_m = 1.0;
  const auto pts = shifted(test::sample_scene(kScenePoints, 41, 0.02f), {-350.0f, 120.0f, -4.0f});
  const Eigen::Vector3f origin(-340.0f, 125.0f, 0.0f);
  exec::CpuExecutor ex(2);
  map::VoxelMap cpu(cfg, ex);
  cpu.insert(pts, origin, map::PointLimit::constant(20));
  // short keys of 30 bits (500 m at 1 m voxels) and of 42 bits (5 km)
  constexpr double kAllWithin_m = 500.0, kWideWithin_m = 5000.0, kFewWithin_m = 3.0;
  const auto bits = [&](double within_m) {
    return map::KeyWindow::around(origin.cast<double>(), within_m, 1.0 / cfg.voxel_size_m).total_bits();
  };
  ASSERT_EQ(bits(kAllWithin_m), 30);
  ASSERT_EQ(bits(kWideWithin_m), 42);
  for (const double within_m : {kAllWithin_m, kWideWithin_m, kFewWithin_m}) {
    SCOPED_TRACE("within " + std::to_string(within_m) + " m");
    test::DeviceMapRig gpu(cfg, kVoxelCapacity);
    gpu.insert(pts, origin, map::PointLimit::constant(20), within_m);
    expect_same_maps(cpu.snapshot(), gpu.map.snapshot());
  }
}

TEST(CudaMap, QueuedUpdatesReadBackInOneWaitAsTheCpuCountsThem) {
  // insertion, removal, the points stored and the density queued, their counts read back together
  // (as the backend's map update does); the free list they leave serves the next insertion
  FARLIO_REQUIRE_GPU();
  RemovalMaps maps;
  map::VoxelMap& cpu = maps.cpu;
  test::DeviceMapRig& gpu = maps.gpu;
  const map::PointLimit& asmd = kDecayingLimit;
  const auto a = test::sample_scene(kScenePoints, 51, 0.02f);
  const auto b = shifted(test::sample_scene(kScenePoints, 52, 0.02f), {20.0f, 3.0f, 0.0f});
  const auto c = shifted(test::sample_scene(kScenePoints, 53, 0.02f), {45.0f, -2.0f, 0.0f});
  const Eigen::Vector3f far_origin(40.0f, 0.0f, 0.0f);
  constexpr double kDensityRange_m = 20.0;
  cpu.insert(a, Eigen::Vector3f::Zero(), asmd);
  gpu.insert(a, Eigen::Vector3f::Zero(), asmd);

  const map::InsertStats sb = cpu.insert(b, far_origin, asmd);
  const std::size_t removed = cpu.remove_far(far_origin);
  ASSERT_GT(removed, 0u);
  gpu.input.upload(b.data(), b.size(), gpu.executor.stream(), "DeviceMapRig::kMaxPoints");
  gpu.map.insert_async(gpu.input.data(), b.size(), far_origin, asmd);
  gpu.map.remove_far_async(far_origin);
  gpu.map.num_points_async();
  gpu.map.mean_points_per_voxel_async(far_origin, kDensityRange_m);
  cuda::ReadBack& rb = gpu.executor.read_back();
  rb.clear();
  gpu.map.post(rb);
  rb.wait();
  const cuda::MapResults r = gpu.map.settle(rb);
  EXPECT_EQ(r.insert.candidates, sb.candidates);
  EXPECT_EQ(r.insert.inserted, sb.inserted);
  EXPECT_EQ(r.insert.rejected_spacing, sb.rejected_spacing);
  EXPECT_EQ(r.insert.rejected_full, sb.rejected_full);
  EXPECT_EQ(r.insert.out_of_range, sb.out_of_range);
  EXPECT_EQ(r.insert.new_voxels, sb.new_voxels);
  EXPECT_EQ(r.insert.covariances_computed, sb.covariances_computed);
  EXPECT_EQ(r.removed_voxels, removed);
  EXPECT_EQ(r.points, cpu.num_points());
  EXPECT_DOUBLE_EQ(r.mean_points_per_voxel, cpu.mean_points_per_voxel(far_origin, kDensityRange_m));
  EXPECT_EQ(gpu.map.num_voxels(), cpu.num_voxels());

  EXPECT_EQ(cpu.insert(c, far_origin, asmd).new_voxels, gpu.insert(c, far_origin, asmd).new_voxels);
  expect_same_maps(cpu.snapshot(), gpu.map.snapshot());
}

TEST(CudaMap, AGatherBeyondItsDestinationIsACapacityErrorThatWritesNothingBeyond) {
  FARLIO_REQUIRE_GPU();
  test::DeviceMapRig gpu(VoxelMapConfig{}, kVoxelCapacity);
  gpu.insert(test::sample_scene(kScenePoints, 61, 0.02f), Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  const std::size_t stored = gpu.map.num_points();
  ASSERT_GT(stored, 1000u);
  const std::size_t capacity = stored / 2;
  cuda::DeviceBuffer<Eigen::Vector4f> points(stored, "points");
  cuda::DeviceBuffer<map::Cov3> covs(stored, "points");
  constexpr int kAllOnes = 0xFF;  // NaN in every float: what a write would replace
  FARLIO_CUDA_CHECK(cudaMemsetAsync(points.data(), kAllOnes, points.bytes(), gpu.executor.stream()));
  FARLIO_CUDA_CHECK(cudaMemsetAsync(covs.data(), kAllOnes, covs.bytes(), gpu.executor.stream()));
  try {
    gpu.map.gather(points.data(), covs.data(), capacity, "test gather capacity");
    FAIL() << "expected CapacityError";
  } catch (const CapacityError& e) {
    EXPECT_NE(std::string(e.what()).find("test gather capacity"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(stored)), std::string::npos) << e.what();
  }
  std::vector<Eigen::Vector4f> host(stored);
  points.download(host.data(), stored, gpu.executor.stream());
  for (std::size_t i = 0; i < stored; ++i) {
    ASSERT_EQ(i < capacity, !host[i].array().isNaN().any()) << "point " << i << " of capacity " << capacity;
  }
  EXPECT_EQ(gpu.map.gather(points.data(), covs.data(), stored, "test gather capacity"), stored);
}
