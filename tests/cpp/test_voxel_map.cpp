// The voxel hash map against brute force and its invariants (cap, spacing, removal, probing).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <random>

#include "farlio/core/error.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/voxel_map.hpp"

using namespace farlio;
using namespace farlio::map;

namespace {

std::vector<Eigen::Vector3f> random_cloud(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Eigen::Vector3f> pts(n);
  for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
  return pts;
}

struct Stored {
  std::vector<Eigen::Vector3f> points;
};

Stored stored_points(const VoxelMap& m) {
  Stored s;
  m.for_each_point([&](const Eigen::Vector3f& p, const Cov3&, bool) { s.points.push_back(p); });
  return s;
}

// The 27-voxel neighbourhood of q, brute force.
bool in_neighbourhood(const Eigen::Vector3f& q, const Eigen::Vector3f& p, float voxel) {
  const VoxelCoord a = voxel_of(q, 1.0f / voxel), b = voxel_of(p, 1.0f / voxel);
  return (a - b).cwiseAbs().maxCoeff() <= 1;
}

VoxelMapConfig small_config() {
  VoxelMapConfig c;
  c.voxel_size_m = 1.0;
  c.max_points_per_voxel = 20;
  c.covariance_neighbors = 10;
  c.initial_voxel_capacity = 16;
  return c;
}

}  // namespace

TEST(VoxelMap, CapAndSpacingHold) {
  exec::CpuExecutor ex(2);
  VoxelMap m(small_config(), ex);
  const auto pts = random_cloud(20000, 5.0f, 1);
  const auto stats = m.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  EXPECT_EQ(stats.inserted + stats.rejected_full + stats.rejected_spacing + stats.out_of_range, pts.size());
  EXPECT_GT(stats.rejected_full + stats.rejected_spacing, 0u);
  EXPECT_EQ(m.num_points(), stats.inserted);
  // every voxel holds <= cap points, pairwise at least the spacing apart
  const float spacing = m.spacing_m();
  EXPECT_NEAR(spacing, 1.0f / std::sqrt(20.0f), 1e-6f);
  const MapView v = m.view();
  std::size_t voxels = 0;
  for (std::size_t vox = 0; vox < m.voxel_capacity(); ++vox) {
    const int n = v.voxel_counts[vox];
    if (n == 0) continue;
    ++voxels;
    ASSERT_LE(n, 20);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3f pi = v.points[v.point_index(static_cast<int>(vox), i)].head<3>();
      ASSERT_EQ(voxel_of(pi, 1.0f), unpack_key(v.voxel_keys[vox]));  // in its own voxel
      for (int j = i + 1; j < n; ++j) {
        ASSERT_GE((pi - v.points[v.point_index(static_cast<int>(vox), j)].head<3>()).norm(), spacing);
      }
    }
  }
  EXPECT_EQ(voxels, m.num_voxels());
}

TEST(VoxelMap, ContentsDoNotDependOnThreadCount) {
  const auto pts = random_cloud(30000, 8.0f, 2);
  exec::CpuExecutor one(1), two(2);
  VoxelMap a(small_config(), one), b(small_config(), two);
  a.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  b.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  auto pa = stored_points(a).points, pb = stored_points(b).points;
  ASSERT_EQ(pa.size(), pb.size());
  auto less = [](const Eigen::Vector3f& x, const Eigen::Vector3f& y) {
    return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3);
  };
  std::sort(pa.begin(), pa.end(), less);
  std::sort(pb.begin(), pb.end(), less);
  for (std::size_t i = 0; i < pa.size(); ++i) ASSERT_EQ(pa[i], pb[i]);
}

TEST(VoxelMap, InsertionWithoutCovariancesStoresTheSamePoints) {
  // CovarianceUpdate::Skip (the first scan's frame map): the same points in the same voxels and
  // order, none with a covariance; the default computes them
  const auto pts = random_cloud(20000, 6.0f, 4);
  exec::CpuExecutor ex(2);
  VoxelMap with(small_config(), ex), without(small_config(), ex);
  const InsertStats sw = with.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  const InsertStats so = without.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20), CovarianceUpdate::Skip);
  EXPECT_EQ(so.inserted, sw.inserted);
  EXPECT_EQ(so.rejected_spacing, sw.rejected_spacing);
  EXPECT_EQ(so.new_voxels, sw.new_voxels);
  EXPECT_EQ(sw.covariances_computed, sw.inserted);
  EXPECT_EQ(so.covariances_computed, 0u);
  const MapSnapshot a = with.snapshot(), b = without.snapshot();
  ASSERT_EQ(a.voxel_keys, b.voxel_keys);
  ASSERT_EQ(a.voxel_counts, b.voxel_counts);
  std::size_t with_covariance = 0;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    ASSERT_EQ(a.points[i].head<3>(), b.points[i].head<3>()) << i;
    EXPECT_FALSE(has_covariance(b.points[i])) << i;
    with_covariance += has_covariance(a.points[i]) ? 1 : 0;
  }
  EXPECT_GT(with_covariance, sw.inserted / 2);
}

TEST(VoxelMap, AdaptiveLimitDecaysWithRange) {
  PointLimit lim{20, 20.0f, 0.03f, 10};
  EXPECT_EQ(lim.at(5.0f), 20);
  EXPECT_EQ(lim.at(20.0f), 20);
  EXPECT_EQ(lim.at(120.0f), 17);   // 20 - 0.03 * 100
  EXPECT_EQ(lim.at(1000.0f), 10);  // floored at k
  // a voxel far away keeps at most the decayed limit
  exec::CpuExecutor ex(2);
  auto cfg = small_config();
  cfg.max_points_per_voxel = 40;
  VoxelMap m(cfg, ex);
  auto pts = random_cloud(5000, 0.5f, 3);
  for (auto& p : pts) p += Eigen::Vector3f(500.5f, 0.5f, 0.5f);
  m.insert(pts, Eigen::Vector3f::Zero(), PointLimit{40, 20.0f, 0.05f, 10});
  EXPECT_LE(static_cast<int>(m.num_points()), 40 - static_cast<int>(0.05f * 480.0f));
}

TEST(VoxelMap, NearestAndKnnEqualBruteForce) {
  exec::CpuExecutor ex(2);
  auto cfg = small_config();
  VoxelMap m(cfg, ex);
  m.insert(random_cloud(15000, 6.0f, 4), Eigen::Vector3f::Zero(), PointLimit::constant(20));
  const auto stored = stored_points(m).points;
  const MapView v = m.view();
  const auto queries = random_cloud(500, 7.0f, 5);
  const int k = 10;
  for (const auto& q : queries) {
    // brute force over the 27-voxel neighbourhood
    std::vector<float> d;
    for (const auto& p : stored) {
      if (in_neighbourhood(q, p, 1.0f)) d.push_back((p - q).squaredNorm());
    }
    std::sort(d.begin(), d.end());
    float nn_d2 = 0;
    const auto nn = nearest_neighbor(v, q, std::numeric_limits<float>::max(), &nn_d2);
    if (d.empty()) {
      EXPECT_EQ(nn, -1);
      continue;
    }
    ASSERT_GE(nn, 0);
    EXPECT_FLOAT_EQ(nn_d2, d.front());
    // with a distance cap
    const float cap = 0.3f;
    const auto capped = nearest_neighbor(v, q, cap * cap);
    EXPECT_EQ(capped >= 0, d.front() < cap * cap);
    std::int64_t idx[kMaxNeighbors];
    float kd[kMaxNeighbors];
    const int found = knn_search(v, q, k, std::numeric_limits<float>::max(), idx, kd);
    ASSERT_EQ(found, std::min<int>(k, static_cast<int>(d.size())));
    for (int i = 0; i < found; ++i) EXPECT_FLOAT_EQ(kd[i], d[static_cast<std::size_t>(i)]);
  }
}

// The k-NN's visit order of the 27 voxels around q, restated: the centre; the 7 voxels of q's
// octant of it (across the nearer face on x, on y, on z; the xy, xz, yz edges; the corner); the
// 19 others by their neighbor_code number.
std::vector<int> knn_visit_order(const Eigen::Vector3f& q, const VoxelCoord& c, float voxel_size) {
  int near[3];
  for (int a = 0; a < 3; ++a) {
    const float inside = q[a] - static_cast<float>(c[a]) * voxel_size;  // 0 .. voxel_size
    near[a] = inside < voxel_size - inside ? -1 : 1;
  }
  const auto n_of = [](int dx, int dy, int dz) {
    for (int n = 0; n < kNeighborVoxels; ++n) {
      if (neighbor_voxel(VoxelCoord::Zero(), n) == VoxelCoord(dx, dy, dz)) return n;
    }
    return -1;
  };
  std::vector<int> order = {0,
                            n_of(near[0], 0, 0),
                            n_of(0, near[1], 0),
                            n_of(0, 0, near[2]),
                            n_of(near[0], near[1], 0),
                            n_of(near[0], 0, near[2]),
                            n_of(0, near[1], near[2]),
                            n_of(near[0], near[1], near[2])};
  for (int n = 1; n < kNeighborVoxels; ++n) {
    if (std::find(order.begin(), order.end(), n) == order.end()) order.push_back(n);
  }
  return order;
}

// Points on a lattice have many exactly equal distances: the k nearest are the first k of the
// candidates in the search's visit order (knn_visit_order, each voxel's points in pool order)
// stably sorted by distance, with and without a distance limit.
TEST(VoxelMap, KnnBreaksDistanceTiesByVisitOrder) {
  exec::CpuExecutor ex(1);
  auto cfg = small_config();
  cfg.point_spacing_m = 0.0;
  VoxelMap m(cfg, ex);
  std::vector<Eigen::Vector3f> lattice;
  constexpr int kSteps = 12;  // 0.25 m apart over 3 m: 2.5 voxels a side
  constexpr float kStep_m = 0.25f;
  for (int x = 0; x < kSteps; ++x)
    for (int y = 0; y < kSteps; ++y)
      for (int z = 0; z < 2; ++z) lattice.emplace_back(kStep_m * x + 0.01f, kStep_m * y + 0.01f, kStep_m * z + 0.01f);
  m.insert(lattice, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  const MapView v = m.view();
  for (const float limit_m : {100.0f, 0.3f}) {
    for (const auto& q : lattice) {
      std::vector<std::pair<float, std::int64_t>> visit;  // (d2, pool index) in visit order
      const VoxelCoord c = voxel_of(q, v.inv_voxel_size);
      const std::vector<int> order = knn_visit_order(q, c, v.voxel_size);
      ASSERT_EQ(order.size(), static_cast<std::size_t>(kNeighborVoxels));
      for (const int n : order) {
        const std::int32_t vox = table_find(v, neighbor_voxel(c, n));
        if (vox < 0) continue;
        for (std::int32_t j = 0; j < v.voxel_counts[vox]; ++j) {
          const std::int64_t i = v.point_index(vox, j);
          const float d2 = (v.points[i].head<3>() - q).squaredNorm();
          if (d2 < limit_m * limit_m) visit.emplace_back(d2, i);
        }
      }
      std::stable_sort(visit.begin(), visit.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      const int k = 10;
      std::int64_t idx[kMaxNeighbors];
      float kd[kMaxNeighbors];
      const int found = knn_search(v, q, k, limit_m * limit_m, idx, kd);
      ASSERT_EQ(found, std::min<int>(k, static_cast<int>(visit.size())));
      for (int i = 0; i < found; ++i) {
        EXPECT_EQ(idx[i], visit[static_cast<std::size_t>(i)].second) << "rank " << i;
        EXPECT_EQ(kd[i], visit[static_cast<std::size_t>(i)].first);
      }
    }
  }
}

TEST(VoxelMap, ForcedCollisionsInASmallTable) {
  exec::CpuExecutor ex(2);
  auto cfg = small_config();
  cfg.initial_voxel_capacity = 4;
  VoxelMap m(cfg, ex);
  m.set_table_capacity_for_testing(16);  // grows as voxels arrive: every insert probes
  const auto pts = random_cloud(3000, 10.0f, 6);
  m.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  // every voxel that received a point is found, and holds the point's voxel key
  const MapView v = m.view();
  for (const auto& p : pts) {
    const auto vox = table_find(v, voxel_of(p, 1.0f));
    ASSERT_GE(vox, 0);
    EXPECT_EQ(unpack_key(v.voxel_keys[vox]), voxel_of(p, 1.0f));
  }
  EXPECT_LE(m.num_voxels() * 2, m.table_capacity());
}

TEST(VoxelMap, RemovesFarVoxelsOnly) {
  exec::CpuExecutor ex(2);
  auto cfg = small_config();
  cfg.removal_radius_m = 10.0;
  VoxelMap m(cfg, ex);
  std::vector<Eigen::Vector3f> pts;
  for (int i = -30; i <= 30; ++i) pts.emplace_back(static_cast<float>(i) + 0.5f, 0.5f, 0.5f);
  m.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  ASSERT_EQ(m.num_voxels(), pts.size());
  const Eigen::Vector3f origin(5.0f, 0.0f, 0.0f);
  const auto removed = m.remove_far(origin);
  std::size_t expected_kept = 0;
  for (const auto& p : pts) expected_kept += (p - origin).norm() <= 10.0f ? 1 : 0;
  EXPECT_EQ(m.num_voxels(), expected_kept);
  EXPECT_EQ(removed, pts.size() - expected_kept);
  // removed voxels are gone from the table, kept ones are found; re-insertion reuses the pool
  const MapView v = m.view();
  for (const auto& p : pts) EXPECT_EQ(table_find(v, voxel_of(p, 1.0f)) >= 0, (p - origin).norm() <= 10.0f);
  const auto cap_before = m.voxel_capacity();
  m.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(20));
  EXPECT_EQ(m.num_voxels(), pts.size());
  EXPECT_EQ(m.voxel_capacity(), cap_before);
}

TEST(VoxelMap, InsertRemoveCyclesKeepTheTableAtItsSize) {
  // a drive: the map slides along x, far voxels leave and erased slots pile up; rehashing drops
  // them in place, the table stays kSlotsPerVoxel x the pool (as on the GPU, whose table is fixed)
  exec::CpuExecutor ex(2);
  auto cfg = small_config();
  cfg.removal_radius_m = 6.0;
  cfg.initial_voxel_capacity = 1024;
  VoxelMap m(cfg, ex);
  const std::size_t table = m.table_capacity();
  ASSERT_EQ(table, table_capacity_for(m.voxel_capacity()));
  for (int step = 0; step < 200; ++step) {
    const Eigen::Vector3f origin(0.5f * static_cast<float>(step), 0.0f, 0.0f);
    auto pts = random_cloud(400, 5.0f, static_cast<unsigned>(step));
    for (auto& p : pts) p += origin;
    m.insert(pts, origin, PointLimit::constant(20));
    m.remove_far(origin);
    ASSERT_EQ(m.voxel_capacity(), 1024u) << "step " << step;
    ASSERT_EQ(m.table_capacity(), table) << "step " << step;
  }
}

TEST(VoxelMap, GrowthBeyondTheLimitIsAClearError) {
  exec::CpuExecutor ex(1);
  auto cfg = small_config();
  cfg.initial_voxel_capacity = 8;
  cfg.max_voxel_capacity = 64;
  VoxelMap m(cfg, ex);
  try {
    m.insert(random_cloud(5000, 20.0f, 7), Eigen::Vector3f::Zero(), PointLimit::constant(20));
    FAIL() << "expected CapacityError";
  } catch (const CapacityError& e) {
    EXPECT_NE(std::string(e.what()).find("max_voxel_capacity"), std::string::npos);
  }
}

TEST(VoxelMap, CovarianceOfAPlaneIsFlat) {
  exec::CpuExecutor ex(2);
  VoxelMapConfig cfg;  // paper defaults: 4 m voxels, 40 points, k = 10
  VoxelMap m(cfg, ex);
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 20000; ++i) pts.emplace_back(u(rng), u(rng), 0.01f * u(rng) / 10.0f + 2.0f);
  m.insert(pts, Eigen::Vector3f::Zero(), PointLimit::constant(40));
  std::size_t valid = 0;
  m.for_each_point([&](const Eigen::Vector3f&, const Cov3& c, bool ok) {
    if (!ok) return;
    ++valid;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> es(c.matrix());
    const Eigen::Vector3f normal = es.eigenvectors().col(0);
    EXPECT_GT(std::abs(normal.z()), 0.99f);  // smallest axis is the plane normal
    EXPECT_LT(es.eigenvalues()(0) / es.eigenvalues()(2), 0.05f);
    EXPECT_NEAR(c.matrix().inverse().norm(), 1.0f, 1e-3f);  // Frobenius normalisation: ||Sigma^-1||_F = 1
    EXPECT_EQ(classify_shape(c.matrix(), 10.0f), PointShape::Surface);
  });
  EXPECT_GT(valid, m.num_points() * 9 / 10);
}

TEST(Covariance, ClosedFormEigenvaluesEqualEigensSolver) {
  std::mt19937 rng(3);
  std::normal_distribution<float> g(0.0f, 1.0f);
  for (int trial = 0; trial < 500; ++trial) {
    Eigen::Matrix3f a;
    for (int i = 0; i < 9; ++i) a.data()[i] = g(rng);
    // spread the scales as regularised covariances have them (1 to 1e3)
    const Eigen::Vector3f scale(1.0f, std::exp(3.0f * std::abs(g(rng))), std::exp(4.0f * std::abs(g(rng))));
    const Eigen::Matrix3f q = a.householderQr().householderQ();
    const Eigen::Matrix3f m = q * scale.asDiagonal() * q.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m.cast<double>());
    const Eigen::Vector3f ours = symmetric_eigenvalues(m);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(ours(k), es.eigenvalues()(k), 1e-4 * es.eigenvalues()(2)) << m;
  }
  EXPECT_TRUE(symmetric_eigenvalues(2.0f * Eigen::Matrix3f::Identity()).isApproxToConstant(2.0f));
}

TEST(Covariance, ShapeOfRegularisedCovariancesAgreesWithADoubleSolver) {
  // the shape test on covariances as the maps make them (spreads 0.01 to 1 m^2, a third of them
  // line-like, eps = 1e-3, Frobenius-normalised) against the same test on a double-precision
  // solver's eigenvalues: float rounding may flip a shape only right at the ratio
  std::mt19937 rng(12);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float eps = 1e-3f, ratio = 10.0f;
  int lines = 0, disagreements = 0;
  constexpr int kTrials = 20000;
  for (int trial = 0; trial < kTrials; ++trial) {
    Eigen::Matrix3f a;
    for (int i = 0; i < 9; ++i) a.data()[i] = g(rng);
    const Eigen::Matrix3f q = a.householderQr().householderQ();
    const float e2 = 0.01f + u(rng), e1 = e2 * (trial % 3 == 0 ? 1e-3f * u(rng) : u(rng)), e0 = e1 * u(rng) * u(rng);
    const Eigen::Matrix3f sample = q * Eigen::Vector3f(e0, e1, e2).asDiagonal() * q.transpose();
    const Eigen::Matrix3f c = regularize_frobenius(0.5f * (sample + sample.transpose()), eps);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(c.cast<double>());
    const Eigen::Vector3d ev = es.eigenvalues();
    const bool line = ev(1) < ratio * ev(0) && ev(2) > ratio * ev(0);
    lines += line ? 1 : 0;
    disagreements += (classify_shape(c, ratio) == PointShape::Line) != line ? 1 : 0;
  }
  EXPECT_GT(lines, kTrials / 4);  // both shapes are exercised
  EXPECT_LT(lines, 3 * kTrials / 4);
  EXPECT_LE(disagreements, kTrials / 1000);
}

TEST(Covariance, ShapeOfLinesAndPlanes) {
  const float eps = 1e-3f;
  Eigen::Matrix3f line = Eigen::Matrix3f::Zero(), plane = Eigen::Matrix3f::Zero();
  line(1, 1) = 1.0f;                 // 1 m spread along y, nothing across
  plane(0, 0) = plane(1, 1) = 0.5f;  // a plane z = const
  EXPECT_EQ(classify_shape(regularize_frobenius(line, eps), 10.0f), PointShape::Line);
  EXPECT_EQ(classify_shape(regularize_frobenius(plane, eps), 10.0f), PointShape::Surface);
  EXPECT_EQ(classify_shape(regularize_frobenius(line, eps), 0.0f), PointShape::Surface);  // classification off
  // a "line" 10 cm wide is a surface strip at the default ratio
  Eigen::Matrix3f strip = line;
  strip(0, 0) = 0.01f;
  EXPECT_EQ(classify_shape(regularize_frobenius(strip, eps), 10.0f), PointShape::Surface);
}

TEST(HashTable, LinearProbingSurvivesCollisionsAndErasure) {
  // 16 slots, 15 keys: nearly every insert collides; erasing must not break probe chains.
  std::vector<std::uint64_t> keys(16, kEmptyKey);
  std::vector<std::int32_t> vox(16, -1);
  MapView v;
  v.slot_keys = keys.data();
  v.slot_voxels = vox.data();
  v.table_capacity = 16;
  std::vector<VoxelCoord> coords;
  for (int i = 0; i < 15; ++i) coords.emplace_back(i * 7 - 50, i % 3, -i);
  for (int i = 0; i < 15; ++i) {
    ASSERT_GE(table_insert(v, pack_key(coords[i]), spatial_hash(coords[i]), i), 0);
    ASSERT_GE(table_insert(v, pack_key(coords[i]), spatial_hash(coords[i]), 99), 0);  // duplicate: no-op
  }
  for (int i = 0; i < 15; ++i) EXPECT_EQ(table_find(v, coords[i]), i);
  for (int i = 0; i < 15; i += 2) EXPECT_TRUE(table_erase(v, pack_key(coords[i]), spatial_hash(coords[i])));
  for (int i = 0; i < 15; ++i) EXPECT_EQ(table_find(v, coords[i]), i % 2 ? i : -1);
  EXPECT_EQ(table_find(v, VoxelCoord(1000, 1000, 1000)), -1);  // absent key in a table without empty slots ends
  const VoxelCoord extra(3, 3, 3);
  EXPECT_GE(table_insert(v, pack_key(extra), spatial_hash(extra), 42), 0);
  EXPECT_EQ(table_find(v, extra), 42);
}

TEST(VoxelKey, PackUnpackRoundTripAndRange) {
  for (const VoxelCoord& c : {VoxelCoord(0, 0, 0), VoxelCoord(-1, -1, -1), VoxelCoord(1048570, -1048570, 12345)}) {
    EXPECT_EQ(unpack_key(pack_key(c)), c);
    EXPECT_NE(pack_key(c), kEmptyKey);
    EXPECT_NE(pack_key(c), kErasedKey);
  }
  EXPECT_FALSE(in_key_range(VoxelCoord(1 << 21, 0, 0)));
  EXPECT_EQ(voxel_of(Eigen::Vector3f(-0.1f, 3.9f, 4.0f), 0.25f), VoxelCoord(-1, 0, 1));
}
