// The real scan pair (../shared/data/real/scan_pair) from perturbed starts (0.5 m, 5 deg).
//
// T_target_source.txt is not an independent ground truth: it is small_gicp's own GICP estimate at
// 0.1 m downsampling (small_gicp reproduces it to 1e-4), and small_gicp's other factors and
// resolutions land 0.06-0.66 deg away from it (figures/odometry_scan_pair.py). The scene leaves the
// rotation weakly constrained at the 0.1-0.3 deg level, so the bounds are: every start converges
// to the same pose (a real property of the basin), within 2 cm / 0.2 deg of the reference with
// 2 m voxels and the paper's sparse-point handling (point-to-point factors, line pairs kept),
// 2 cm / 0.3 deg with farlio's (measured 0.8 cm / 0.20-0.22 deg), and 3.5 cm / 0.4 deg with
// 4 m voxels (measured 2.8 cm / 0.28-0.31 deg).
#include <gtest/gtest.h>

#include <fstream>

#include "farlio/io/point_cloud_io.hpp"
#include "farlio/pipeline/pairwise.hpp"
#include "test_support.hpp"

using namespace farlio;

namespace {
SE3 read_matrix(const std::filesystem::path& p) {
  std::ifstream f(p);
  Mat4d m;
  for (int i = 0; i < 16; ++i) f >> m(i / 4, i % 4);
  EXPECT_FALSE(f.fail()) << p;
  return SE3::from_matrix(m);
}
}  // namespace

struct PairCase {
  double voxel_size_m;
  bool paper_sparse_handling;  ///< point-to-point factors for points without covariance, line pairs kept
  double max_translation_m, max_rotation_deg;
};

class ScanPair : public ::testing::TestWithParam<PairCase> {};

TEST_P(ScanPair, RegistersFromPerturbedStarts) {
  FARLIO_REQUIRE_SHARED_DATA();
  const auto dir = test::shared_data() / "real" / "scan_pair";
  const Scan source = io::read_point_cloud(dir / "source.ply");
  const Scan target = io::read_point_cloud(dir / "target.ply");
  const SE3 truth = read_matrix(dir / "T_target_source.txt");
  const PairCase c = GetParam();
  Config cfg;
  cfg.map.voxel_size_m = c.voxel_size_m;
  cfg.map.auto_voxel_size = false;  // this test is about these voxel sizes
  if (c.paper_sparse_handling) cfg.registration.point_to_point_sigma_m = std::sqrt(cfg.map.covariance_epsilon);
  cfg.registration.skip_line_pairs = !c.paper_sparse_handling;
  std::vector<SE3> results;
  for (const auto& [offset_m, angle_deg] : {std::pair{0.0, 0.0}, {0.5, 0.0}, {0.0, 5.0}, {0.5, 5.0}, {0.5, -5.0}}) {
    Vec6d d;
    d << offset_m * 0.8, -offset_m * 0.6, 0.0, 0.0, 0.0, angle_deg * M_PI / 180.0;
    const auto res = pipeline::register_pair(source.points, target.points, truth * SE3::exp(d), cfg);
    const SE3 err = truth.inverse() * res.pose;
    EXPECT_TRUE(res.converged);
    EXPECT_LT(err.translation().norm(), c.max_translation_m) << offset_m << " m, " << angle_deg << " deg";
    EXPECT_LT(err.angle_rad() * 180.0 / M_PI, c.max_rotation_deg) << offset_m << " m, " << angle_deg << " deg";
    results.push_back(res.pose);
  }
  // one basin: every start ends at the same pose, up to what the paper's convergence norm
  // (|dx| < 5e-3) leaves
  for (const auto& r : results) {
    EXPECT_LT((results.front().inverse() * r).translation().norm(), 0.01);
    EXPECT_LT((results.front().inverse() * r).angle_rad() * 180.0 / M_PI, 0.1);
  }
}

INSTANTIATE_TEST_SUITE_P(Voxels, ScanPair,
                         ::testing::Values(PairCase{4.0, false, 0.035, 0.4}, PairCase{2.0, false, 0.02, 0.3},
                                           PairCase{2.0, true, 0.02, 0.2}));
