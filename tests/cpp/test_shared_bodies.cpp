// The kernel bodies shared by the CPU executor and CUDA (map/voxel_update.hpp,
// registration/factor_sums.hpp, pipeline/range_crop.hpp), run here through the CPU executor
// and directly on small inputs with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "farlio/core/types.hpp"
#include "farlio/exec/cpu_executor.hpp"
#include "farlio/exec/hd_math.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/preprocess/downsampling_keys.hpp"
#include "farlio/preprocess/preprocess_point.hpp"
#include "farlio/preprocess/range_crop.hpp"
#include "farlio/registration/factor_sums.hpp"
#include "farlio/registration/gicp.hpp"
#include "scene_fixture.hpp"

using namespace farlio;

TEST(SharedBodies, PointKeyDropsNonFiniteAndOutOfRangePoints) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(map::point_key({nan, 0, 0}, 1.0f), map::kEmptyKey);
  EXPECT_EQ(map::point_key({1e12f, 0, 0}, 1.0f), map::kEmptyKey);
  EXPECT_EQ(map::point_key({1.5f, -0.5f, 2.0f}, 1.0f), map::pack_key(map::VoxelCoord(1, -1, 2)));
}

TEST(SharedBodies, FinitePointKeepsThePointsThatTheScanKeeps) {
  // the CUDA backend screens a scan on the device with finite_point; the pipeline screens it on
  // the host with Scan::remove_non_finite for the CPU backend: the same points must stay
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  constexpr std::size_t kPoints = 4000;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pick(0, 9);
  std::uniform_real_distribution<float> coord(-50.0f, 50.0f);
  const float specials[] = {nan, inf, -inf, std::numeric_limits<float>::max()};
  Scan scan;
  for (std::size_t i = 0; i < kPoints; ++i) {
    Eigen::Vector3f p(coord(rng), coord(rng), coord(rng));
    float t = 0.05f;
    const int r = pick(rng);
    if (r < 3) p[r] = specials[static_cast<std::size_t>(pick(rng)) % 4];  // a coordinate
    if (r == 3) t = specials[static_cast<std::size_t>(pick(rng)) % 3];    // the time
    scan.points.push_back(p);
    scan.time_s.push_back(t);
  }
  std::vector<Eigen::Vector3f> screened;
  for (std::size_t i = 0; i < kPoints; ++i) {
    if (preprocess::finite_point(scan.points[i], &scan.time_s[i])) screened.push_back(scan.points[i]);
  }
  std::size_t without_times = 0;  // a scan without times: the coordinates alone
  for (const auto& p : scan.points) without_times += preprocess::finite_point(p, nullptr) ? 1 : 0;
  Scan host = scan;
  const std::size_t removed = host.remove_non_finite();
  EXPECT_GT(removed, kPoints / 5);
  EXPECT_EQ(kPoints - removed, screened.size());
  EXPECT_EQ(host.points, screened);
  host = scan;
  host.time_s.clear();
  EXPECT_EQ(kPoints - host.remove_non_finite(), without_times);
}

TEST(SharedBodies, FloorToIntEqualsFloorfOverTheIntRange) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> wide(-2.1e9f, 2.1e9f), narrow(-300.0f, 300.0f);
  std::vector<float> xs = {0.0f,
                           -0.0f,
                           0.5f,
                           -0.5f,
                           1.0f,
                           -1.0f,
                           -1e-30f,
                           1e-30f,
                           16777216.0f,
                           -16777216.0f,
                           -2147483648.0f,
                           2147483520.0f,
                           std::nextafter(-1.0f, 0.0f),
                           std::nextafter(-1.0f, -2.0f),
                           std::nextafter(0.0f, -1.0f)};
  for (int i = 0; i < 100000; ++i) xs.push_back(i % 2 ? wide(rng) : narrow(rng));
  for (const float x : xs) ASSERT_EQ(exec::floor_to_int(x), static_cast<int>(std::floor(x))) << x;
}

TEST(SharedBodies, Log1pOfTheCauchyCostIsWithinFloatPrecision) {
  // exec::log1p_nonnegative replaces log1pf in the Cauchy kernel's cost: within 3e-7 of the
  // exact value relative, from tiny to huge arguments, and on both sides of the sqrt(2) split
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> exponent(-14.0f, 30.0f);
  std::vector<float> xs = {0.0f, 1e-30f, 0.41421356f, 0.41421357f, 1.0f, 2.0f, 3.0f, 1e30f};
  for (int i = 0; i < 200000; ++i) xs.push_back(std::pow(10.0f, exponent(rng)));
  for (const float x : xs) {
    const double exact = std::log1p(static_cast<double>(x));
    EXPECT_NEAR(exec::log1p_nonnegative(x), exact, 3e-7 * exact + 1e-38) << "x = " << x;
  }
  EXPECT_EQ(exec::log1p_nonnegative(std::numeric_limits<float>::infinity()), std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(exec::log1p_nonnegative(std::numeric_limits<float>::quiet_NaN())));
}

TEST(SharedBodies, RangeCropKeepsTheClosedInterval) {
  PreprocessConfig c;
  c.min_range_m = 1.0;
  c.max_range_m = 10.0;
  const auto crop = preprocess::RangeCrop::from(c);
  EXPECT_TRUE(crop.keeps({1.0f, 0, 0}));
  EXPECT_TRUE(crop.keeps({0, 10.0f, 0}));
  EXPECT_FALSE(crop.keeps({0.5f, 0, 0}));
  EXPECT_FALSE(crop.keeps({0, 0, 10.5f}));
  EXPECT_FALSE(crop.keeps({std::numeric_limits<float>::infinity(), 0, 0}));
}

TEST(SharedBodies, DownsamplingKeysOfTheCpuEqualThePerPointBody) {
  // the CPU's batch (SSE2, four points at a time) against downsampling_key, which CUDA runs:
  // ordinary points, points on cell borders and on the crop's bounds, huge, infinite and NaN
  // coordinates, and batch lengths that leave a scalar tail
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-120.0f, 120.0f);
  std::uniform_int_distribution<int> cell(-300, 300), pick(0, 9);
  for (const float cell_m : {0.632f, 0.1f, 2.0f}) {
    PreprocessConfig c;
    c.min_range_m = 1.0;
    c.max_range_m = 100.0;
    preprocess::PreprocessParams pp{preprocess::RangeCrop::from(c), {}, false, 1.0f / cell_m};
    std::vector<Vec3f> pts;
    for (int i = 0; i < 20000; ++i) {
      Vec3f p(u(rng), u(rng), 0.2f * u(rng));
      switch (pick(rng)) {
        case 0: p.x() = static_cast<float>(cell(rng)) * cell_m; break;  // on a cell border
        case 1: p = p.normalized() * 100.0f; break;                     // on the crop's bound
        case 2: p = p.normalized(); break;
        case 3: p.y() = pick(rng) < 5 ? inf : -inf; break;
        case 4: p.z() = nan; break;
        case 5: p *= 1e18f; break;  // a squared range that overflows
        case 6: p.x() = -0.0f; break;
        default: break;
      }
      pts.push_back(p);
    }
    for (const std::size_t n : {pts.size(), std::size_t{7}, std::size_t{3}, std::size_t{0}}) {
      std::vector<std::uint64_t> batch(n, 0);
      preprocess::downsampling_keys(pts.data(), n, pp, batch.data());
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(batch[i], preprocess::downsampling_key(pts[i], pp)) << pts[i].transpose() << " cell " << cell_m;
      }
    }
  }
}

TEST(SharedBodies, VoxelGroupInsertionKeepsOrderCapAndSpacing) {
  // one voxel of a 4 m map, spacing 1 m, at most 3 points
  std::vector<std::uint64_t> slot_keys(16, map::kEmptyKey), voxel_keys(1, map::kEmptyKey);
  std::vector<std::int32_t> slot_voxels(16, -1), counts(1, 0);
  constexpr int kMax = 3;
  std::vector<Eigen::Vector4f> points(kMax, Eigen::Vector4f::Zero());
  std::vector<map::Cov3> covs(kMax);
  map::MapView m{slot_keys.data(),
                 slot_voxels.data(),
                 16,
                 voxel_keys.data(),
                 counts.data(),
                 points.data(),
                 covs.data(),
                 kMax,
                 4.0f,
                 0.25f};
  const std::vector<Eigen::Vector3f> cand = {
      {0.5f, 0.5f, 0.5f}, {0.9f, 0.5f, 0.5f}, {2.0f, 0.5f, 0.5f}, {3.5f, 0.5f, 0.5f}, {0.5f, 3.5f, 0.5f}};
  const map::InsertParams ip{Eigen::Vector3f::Zero(), map::PointLimit::constant(kMax), 1.0f};
  std::int32_t first_new = -1;
  const auto s = map::insert_voxel_group(
      m, 0, [&](std::int64_t c) { return cand[static_cast<std::size_t>(c)]; }, 0,
      static_cast<std::int64_t>(cand.size()), ip, &first_new);
  EXPECT_EQ(first_new, 0);
  EXPECT_EQ(s.inserted, 3);
  EXPECT_EQ(s.spacing, 1);  // (0.9, 0.5, 0.5) is 0.4 m from the first
  EXPECT_EQ(s.full, 1);     // the last comes after the cap
  ASSERT_EQ(counts[0], 3);
  EXPECT_EQ(points[0].head<3>(), cand[0]);
  EXPECT_EQ(points[1].head<3>(), cand[2]);
  EXPECT_EQ(points[2].head<3>(), cand[3]);
}

TEST(SharedBodies, FactorSumsReduceToTheSameSystemAsPerPointSums) {
  exec::CpuExecutor ex(2);
  map::VoxelMap target(VoxelMapConfig{}, ex);
  const auto pts = test::sample_scene(20000, 7);
  target.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  registration::SourceCloud src;
  for (std::size_t i = 0; i < pts.size(); i += 10) {
    src.points.emplace_back(pts[i].x() + 0.05f, pts[i].y(), pts[i].z(), 0.0f);
    src.covs.emplace_back();
  }
  const auto th = registration::Thresholds::from_sigma(1.0);
  const SE3 T;
  const auto sys = registration::build_linear_system(src, target.view(), T, th, RegistrationConfig{}, ex);
  // serial sum of the same per-point bodies
  const auto fp = registration::factor_params(T, th, RegistrationConfig{});
  auto serial = registration::FactorSums::zero();
  for (std::size_t i = 0; i < src.size(); ++i)
    serial += registration::factor_sums(target.view(), src.points[i], src.covs[i], fp);
  const auto ref = registration::to_linear_system(serial);
  EXPECT_EQ(sys.inliers, ref.inliers);
  EXPECT_GT(sys.inliers, 0);
  EXPECT_LT((sys.H - ref.H).norm(), 1e-9 * ref.H.norm());
  EXPECT_LT((sys.b - ref.b).norm(), 1e-9 * (ref.b.norm() + 1.0));
  EXPECT_NEAR(sys.error, ref.error, 1e-9 * (ref.error + 1.0));
}

TEST(SharedBodies, FactorsAddedInPlaceEqualTheReduceOfPerPointSums) {
  // the CPU adds each factor to its task's sums in place (CpuExecutor::accumulate, add_factor);
  // CUDA reduces per-point FactorSums: on the same partition, the same doubles bit for bit
  for (const int threads : {1, 2, 3}) {
    exec::CpuExecutor ex(threads);
    map::VoxelMap target(VoxelMapConfig{}, ex);
    const auto pts = test::sample_scene(20000, 11);
    target.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
    registration::SourceCloud src;
    for (std::size_t i = 0; i < pts.size(); i += 7) {  // some beyond the gate: no correspondence
      src.points.emplace_back(pts[i].x() + (i % 3 == 0 ? 5.0f : 0.05f), pts[i].y(), pts[i].z(), 0.0f);
      src.covs.emplace_back();
    }
    const auto th = registration::Thresholds::from_sigma(0.5);
    const SE3 T = SE3::exp((registration::Vec6d() << 0.02, -0.01, 0.0, 0.0, 0.0, 0.01).finished());
    const auto sys = registration::build_linear_system(src, target.view(), T, th, RegistrationConfig{}, ex);
    const auto fp = registration::factor_params(T, th, RegistrationConfig{});
    const map::ConstMapView v = target.view();
    const auto sums = ex.reduce(
        src.size(), registration::FactorSums::zero(),
        [&](std::size_t i) { return registration::factor_sums(v, src.points[i], src.covs[i], fp); },
        registration::AddFactorSums{});
    const auto ref = registration::to_linear_system(sums);
    EXPECT_GT(sys.inliers, 0);
    EXPECT_LT(sys.inliers, static_cast<long>(src.size()));
    EXPECT_EQ(sys.inliers, ref.inliers) << threads << " threads";
    EXPECT_TRUE(sys.H == ref.H) << threads << " threads";
    EXPECT_TRUE(sys.b == ref.b) << threads << " threads";
    EXPECT_EQ(sys.error, ref.error) << threads << " threads";
  }
}

TEST(SharedBodies, CovariancesFromTheNeighbourhoodLookedUpOnceEqualThoseOfEachPointsOwnLookups) {
  // both backends compute a voxel's covariances with its 27 neighbours looked up once (the CPU a
  // voxel a task, CUDA a point a lane); each point's own lookups (knn_search without the
  // neighbourhood, as the registration searches) give bit-identical covariances and shapes
  exec::CpuExecutor ex(2);
  VoxelMapConfig cfg;
  cfg.max_points_per_voxel = 20;
  map::VoxelMap frame(cfg, ex);
  frame.insert(test::sample_scene(30000, 5), Eigen::Vector3f::Zero(), map::PointLimit::constant(20));
  const map::MapSnapshot cpu = frame.snapshot();
  const map::MapView v = frame.view();
  std::size_t compared = 0, with_covariance = 0;
  for (std::size_t vox = 0; vox < cpu.voxel_keys.size(); ++vox) {
    for (std::int32_t j = 0; j < cpu.voxel_counts[vox]; ++j) {
      const int neighbors = cfg.covariance_neighbors;
      map::point_covariance(v, static_cast<std::int32_t>(vox), j, neighbors, static_cast<float>(cfg.covariance_epsilon),
                            static_cast<float>(cfg.line_eigenvalue_ratio),
                            [&](const Eigen::Vector3f& p, std::int64_t* idx, float* d2) {
                              return map::knn_search(v, p, neighbors, map::kUnboundedDistance2, idx, d2);
                            });
      const std::int64_t i = v.point_index(static_cast<std::int32_t>(vox), j);
      const auto k = static_cast<std::size_t>(i);
      ASSERT_EQ(v.points[i].w(), cpu.points[k].w()) << "voxel " << vox << " point " << j;
      if (map::has_covariance(cpu.points[k])) {
        EXPECT_EQ(v.covs[i].matrix(), cpu.covs[k].matrix());
        ++with_covariance;
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 2000u);
  EXPECT_GT(with_covariance, compared / 2);
}

namespace {

/// Squared distance from p to the box of voxel c, axis by axis (the form the searches used
/// before BlockDistances).
float voxel_box_distance2(const Eigen::Vector3f& p, const map::VoxelCoord& c, float voxel_size) {
  float d2 = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const float lo = static_cast<float>(c[a]) * voxel_size;
    const float hi = lo + voxel_size;
    const float d = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0f);
    d2 += d * d;
  }
  return d2;
}

}  // namespace

TEST(SharedBodies, BlockDistancesEqualTheBoxDistanceOfEachVoxel) {
  // the neighbour searches prune voxels with BlockDistances: the same floats as the box
  // distance per voxel, so the voxels visited (and the matches) do not change
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-300.0f, 300.0f);
  for (float voxel : {4.0f, 1.0f, 0.37f}) {
    for (int q = 0; q < 2000; ++q) {
      const Eigen::Vector3f p(u(rng), u(rng), 0.1f * u(rng));
      const map::VoxelCoord c0 = map::voxel_of(p, 1.0f / voxel);
      const map::BlockDistances box(p, c0, voxel);
      float nearest_other = std::numeric_limits<float>::max();
      for (int n = 0; n < map::kNeighborVoxels; ++n) {
        ASSERT_EQ(box.distance2(n), voxel_box_distance2(p, map::neighbor_voxel(c0, n), voxel)) << n;
        if (n > 0) nearest_other = std::min(nearest_other, box.distance2(n));
      }
      EXPECT_EQ(box.distance2(0), 0.0f);
      // the searches stop after the centre when their bound is within the nearest face: exact,
      // because none of the other 26 voxels is nearer
      EXPECT_LE(box.nearest_face2(), nearest_other);
    }
  }
}
