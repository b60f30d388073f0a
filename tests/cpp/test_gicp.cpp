// Sparsity-aware GICP: known transforms from perturbed starts, the point-to-point fallback,
// the time budget, and the adaptive threshold.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <random>

#include "farlio/map/voxel_map.hpp"
#include "farlio/registration/adaptive_threshold.hpp"
#include "farlio/registration/gicp.hpp"
#include "farlio/registration/gicp_factor.hpp"
#include "scene_fixture.hpp"

using namespace farlio;
using namespace farlio::registration;

namespace {

// These tests are about accuracy, not timing (sanitizer builds are slow): no time budget.
constexpr double kNoBudget = std::numeric_limits<double>::infinity();

struct Problem {
  exec::CpuExecutor ex{2};
  map::VoxelMap target{VoxelMapConfig{}, ex};
  map::VoxelMap frame;
  SourceCloud source;
  SE3 truth;

  static VoxelMapConfig frame_config() {
    VoxelMapConfig c;
    c.max_points_per_voxel = 20;
    return c;
  }
  Problem(const SE3& t, bool sparse_source = false) : frame(frame_config(), ex), truth(t) {
    target.insert(test::sample_scene(120000, 1), Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
    auto src_world = test::sample_scene(60000, 2, 0.01f);
    if (sparse_source) {  // dense on the left half, a few isolated floor points on the right
      std::erase_if(src_world, [](const Eigen::Vector3f& p) { return p.x() > 0.0f; });
      for (int i = 0; i < 40; ++i) {
        src_world.emplace_back(10.0f + 0.35f * static_cast<float>(i % 5 * 8), -24.0f + 1.2f * static_cast<float>(i),
                               0.0f);
      }
    }
    std::vector<Eigen::Vector3f> src_sensor;
    const SE3 inv = t.inverse();
    for (const auto& p : src_world) src_sensor.push_back((inv * p.cast<double>()).cast<float>());
    frame.insert(src_sensor, Eigen::Vector3f::Zero(), map::PointLimit::constant(20));
    source = source_from_map(frame.view(), frame.voxel_capacity());
  }
};

SE3 make_pose(double x, double y, double z, double yaw_deg, double roll_deg = 0) {
  Vec6d xi;
  xi << x, y, z, roll_deg * M_PI / 180.0, 0, yaw_deg * M_PI / 180.0;
  return SE3(SE3::exp(xi).quaternion(), Eigen::Vector3d(x, y, z));
}

double trans_err(const SE3& a, const SE3& b) { return (a.inverse() * b).translation().norm(); }
double rot_err_deg(const SE3& a, const SE3& b) { return (a.inverse() * b).angle_rad() * 180.0 / M_PI; }

}  // namespace

class GicpRecovers : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(GicpRecovers, KnownTransformFromPerturbedStart) {
  const auto [offset_m, angle_deg] = GetParam();
  Problem pb(make_pose(1.5, -0.7, 0.4, 20.0, 2.0));
  Vec6d d;
  d << offset_m / std::sqrt(3.0), -offset_m / std::sqrt(3.0), offset_m / std::sqrt(3.0), 0.3 * angle_deg * M_PI / 180.0,
      -0.3 * angle_deg * M_PI / 180.0, 0.9 * angle_deg * M_PI / 180.0;
  const SE3 guess = pb.truth * SE3::exp(d);
  ASSERT_GT(pb.source.size(), 1000u);
  RegistrationConfig cfg;
  const auto res =
      register_scan(pb.source, pb.target.view(), guess, Thresholds::from_sigma(1.0), cfg, kNoBudget, pb.ex);
  EXPECT_TRUE(res.converged);
  EXPECT_LT(trans_err(res.pose, pb.truth), 0.02) << "iterations " << res.iterations;
  EXPECT_LT(rot_err_deg(res.pose, pb.truth), 0.1);
  EXPECT_GT(res.system.inliers, static_cast<long>(pb.source.size() * 8 / 10));
  // the returned H is the Gauss-Newton information: symmetric positive definite here
  EXPECT_LT((res.system.H - res.system.H.transpose()).norm(), 1e-9 * res.system.H.norm());
  EXPECT_GT(res.system.H.ldlt().vectorD().minCoeff(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Perturbations, GicpRecovers,
                         ::testing::Values(std::make_tuple(0.0, 0.0), std::make_tuple(0.5, 0.0),
                                           std::make_tuple(0.0, 5.0), std::make_tuple(0.5, 5.0)));

TEST(Gicp, CorrespondenceReuseKeepsTheResultAndStaleMatchesWouldNot) {
  Problem pb(make_pose(1.5, -0.7, 0.4, 20.0, 2.0));
  Vec6d d;
  d << 0.3, -0.3, 0.3, 0.02, -0.02, 0.08;
  const SE3 guess = pb.truth * SE3::exp(d);
  const auto run = [&](double reuse_m) {
    RegistrationConfig cfg;
    cfg.correspondence_reuse_m = reuse_m;
    return register_scan(pb.source, pb.target.view(), guess, Thresholds::from_sigma(1.0), cfg, kNoBudget, pb.ex);
  };
  const auto fresh = run(0.0), reused = run(RegistrationConfig{}.correspondence_reuse_m), stale = run(1e3);
  ASSERT_TRUE(fresh.converged && reused.converged);
  EXPECT_LT(trans_err(reused.pose, pb.truth), 0.02);
  EXPECT_LT(rot_err_deg(reused.pose, pb.truth), 0.1);
  EXPECT_LT(trans_err(reused.pose, fresh.pose), 0.005);
  // never searching again after the first iteration (matches from 0.5 m off) ends elsewhere:
  // the reuse distance is what keeps the matches current
  EXPECT_GT(trans_err(stale.pose, pb.truth), 2.0 * std::max(trans_err(reused.pose, pb.truth), 0.005));
}

TEST(Gicp, CoarseIterationsFromAFarGuessEndWhereAllPointsDo) {
  Problem pb(make_pose(1.5, -0.7, 0.4, 20.0, 2.0));
  const auto run = [&](const SE3& guess, int stride) {
    RegistrationConfig cfg;
    cfg.coarse_stride = stride;
    return register_scan(pb.source, pb.target.view(), guess, Thresholds::from_sigma(1.0), cfg, kNoBudget, pb.ex);
  };
  Vec6d far_off;
  far_off << 0.5, -0.4, 0.2, 0.02, -0.02, 0.08;
  const SE3 far = pb.truth * SE3::exp(far_off);
  const auto fine = run(far, 1), coarse = run(far, RegistrationConfig{}.coarse_stride);
  ASSERT_TRUE(fine.converged && coarse.converged);
  EXPECT_EQ(fine.coarse_iterations, 0);
  EXPECT_GT(coarse.coarse_iterations, 0);                  // the first step is longer than coarse_step_norm
  EXPECT_LT(coarse.coarse_iterations, coarse.iterations);  // the last iterations use every point
  EXPECT_LT(trans_err(coarse.pose, pb.truth), 0.02);
  EXPECT_LT(rot_err_deg(coarse.pose, pb.truth), 0.1);
  EXPECT_LT(trans_err(coarse.pose, fine.pose), 0.005);
  // the system returned is that of all points at the end, as without coarse iterations
  EXPECT_NEAR(static_cast<double>(coarse.system.inliers), static_cast<double>(fine.system.inliers),
              0.01 * static_cast<double>(fine.system.inliers));
  EXPECT_GT(coarse.system.inliers, static_cast<long>(pb.source.size() * 8 / 10));

  // a near guess: its first step is short, so no coarse iteration, and the very same result
  Vec6d near_off;
  near_off << 0.01, -0.01, 0.0, 0.0, 0.0, 0.002;
  const SE3 near = pb.truth * SE3::exp(near_off);
  const auto near_fine = run(near, 1), near_coarse = run(near, RegistrationConfig{}.coarse_stride);
  EXPECT_EQ(near_coarse.coarse_iterations, 0);
  EXPECT_EQ(near_coarse.iterations, near_fine.iterations);
  EXPECT_EQ(near_coarse.pose.matrix(), near_fine.pose.matrix());
}

TEST(Gicp, StridedCountVisitsEveryStrideThPoint) {
  EXPECT_EQ(strided_count(0, 4), 0u);
  EXPECT_EQ(strided_count(1, 4), 1u);
  EXPECT_EQ(strided_count(8, 4), 2u);
  EXPECT_EQ(strided_count(9, 4), 3u);  // 0, 4, 8
  EXPECT_EQ(strided_count(9, 1), 9u);
}

TEST(Gicp, PointToPointFallbackWithoutCovariance) {
  // A source point without a covariance is weighted by Omega = lambda I (Sigma_s = 0): the
  // paper's lambda = 1 here.
  exec::CpuExecutor ex(1);
  map::VoxelMap target(VoxelMapConfig{}, ex);
  target.insert(test::sample_scene(60000, 3), Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  FactorParams fp{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.05f, 0.0f, 0.0f), 4.0f, CauchyKernel{1e6f}, true};
  const Eigen::Vector4f with_cov(3.0f, 2.0f, 0.0f, 1.0f), without(3.0f, 2.0f, 0.0f, 0.0f);
  map::Cov3 c = map::Cov3::from(Eigen::Matrix3f::Identity() * 0.01f);
  FactorTerms f_cov{}, f_p2p{};
  ASSERT_TRUE(gicp_factor(target.view(), with_cov, c, fp, f_cov));
  ASSERT_TRUE(gicp_factor(target.view(), without, c, fp, f_p2p));
  // point-to-point: the translation block of H is w * I (kernel weight ~1 with a huge kappa)
  EXPECT_NEAR(f_p2p.H[0], 1.0f, 1e-4f);  // H(0,0)
  EXPECT_NEAR(f_p2p.H[1], 0.0f, 1e-6f);  // H(0,1)
  EXPECT_NEAR(f_p2p.H[6], 1.0f, 1e-4f);  // H(1,1)
  // GICP on the floor: the normal direction (z) dominates the information
  EXPECT_GT(f_cov.H[15], 10.0f * f_cov.H[0]);  // H(2,2) >> H(0,0)
  // and with the sparsity-aware switch off, the valid covariance is ignored too
  fp.sparsity_aware = false;
  FactorTerms f_off{};
  ASSERT_TRUE(gicp_factor(target.view(), with_cov, c, fp, f_off));
  for (int k = 0; k < 21; ++k) EXPECT_FLOAT_EQ(f_off.H[k], f_p2p.H[k]);
  // farlio's lambda scales the point-to-point information and nothing else
  fp.sparsity_aware = true;
  fp.point_to_point_precision = 0.03f;
  FactorTerms f_scaled{}, f_cov_again{};
  ASSERT_TRUE(gicp_factor(target.view(), without, c, fp, f_scaled));
  ASSERT_TRUE(gicp_factor(target.view(), with_cov, c, fp, f_cov_again));
  for (int k = 0; k < 21; ++k) EXPECT_NEAR(f_scaled.H[k], 0.03f * f_p2p.H[k], 1e-5f * (1.0f + std::abs(f_p2p.H[k])));
  for (int k = 0; k < 21; ++k) EXPECT_FLOAT_EQ(f_cov_again.H[k], f_cov.H[k]);
}

TEST(Gicp, FactorEqualsTheProductOfItsJacobianAndInformation) {
  // gicp_factor_at forms H and b from A = R^T Omega R without J; the reference forms
  // J = [R, -R [s]x], Omega = (C_q + R C_s R^T)^-1 and w J^T Omega J, w J^T Omega r in double.
  exec::CpuExecutor ex(1);
  map::VoxelMap target(VoxelMapConfig{}, ex);
  target.insert(test::sample_scene(60000, 3), Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  const map::ConstMapView view = target.view();
  std::mt19937 rng(11);
  std::normal_distribution<float> g(0.0f, 1.0f);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3f axis = Eigen::Vector3f(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Matrix3f R = Eigen::AngleAxisf(0.3f * g(rng), axis).toRotationMatrix();
    const Eigen::Vector3f t(0.1f * g(rng), 0.1f * g(rng), 0.05f * g(rng));
    const Eigen::Vector3f sp(15.0f * g(rng), 15.0f * g(rng), 0.5f * std::abs(g(rng)));
    Eigen::Matrix3f a;
    for (int i = 0; i < 9; ++i) a.data()[i] = 0.1f * g(rng);
    const Eigen::Matrix3f cs = a * a.transpose() + 1e-3f * Eigen::Matrix3f::Identity();
    const bool point_to_point = trial % 4 == 0;
    const Eigen::Vector4f s(sp.x(), sp.y(), sp.z(),
                            map::shape_code(point_to_point ? map::PointShape::NoCovariance : map::PointShape::Surface));
    FactorParams fp{R, t, 4.0f, CauchyKernel{0.5f}, true};
    fp.point_to_point_precision = 2.5f;
    const Eigen::Vector3f p = R * sp + t;
    const std::int64_t nn = map::nearest_neighbor(view, p, fp.max_correspondence_distance2);
    FactorTerms f{};
    if (!gicp_factor_at(view, s, map::Cov3::from(cs), p, nn, fp, f)) continue;
    const Eigen::Vector4f& q = view.points[nn];
    const Eigen::Matrix3d Rd = R.cast<double>();
    Eigen::Matrix3d omega = fp.point_to_point_precision * Eigen::Matrix3d::Identity();
    if (map::has_covariance(s) && map::has_covariance(q)) {
      omega = (view.covs[nn].matrix().cast<double>() + Rd * cs.cast<double>() * Rd.transpose()).inverse();
    }
    const Eigen::Vector3d sd = sp.cast<double>();
    Eigen::Matrix3d sx;
    sx << 0.0, -sd.z(), sd.y(), sd.z(), 0.0, -sd.x(), -sd.y(), sd.x(), 0.0;
    Eigen::Matrix<double, 3, 6> J;
    J << Rd, -Rd * sx;
    const Eigen::Vector3d r = (p - q.head<3>()).cast<double>();
    const double w = fp.kernel.weight(static_cast<float>(r.squaredNorm()));
    const Eigen::Matrix<double, 6, 6> H = w * J.transpose() * omega * J;
    const Eigen::Matrix<double, 6, 1> b = w * J.transpose() * omega * r;
    const double h_scale = H.cwiseAbs().maxCoeff(), b_scale = b.cwiseAbs().maxCoeff() + 1e-12;
    int k = 0;
    for (int i = 0; i < 6; ++i) {
      for (int j = i; j < 6; ++j) EXPECT_NEAR(f.H[k++], H(i, j), 2e-5 * h_scale) << "H(" << i << "," << j << ")";
      EXPECT_NEAR(f.b[i], b(i), 2e-5 * b_scale) << "b(" << i << ")";
    }
    ++compared;
  }
  EXPECT_GE(compared, 100);
}

TEST(Gicp, PointToPointPrecisionFollowsTheSpacing) {
  RegistrationConfig cfg;  // sigma = spacing / 2
  EXPECT_NEAR(point_to_point_precision(cfg, 1e-3, 0.632), 1e-3 * 4.0 / (0.632 * 0.632), 1e-12);
  cfg.point_to_point_sigma_m = std::sqrt(1e-3);  // the paper's weighting
  EXPECT_NEAR(point_to_point_precision(cfg, 1e-3, 0.632), 1.0, 1e-12);
}

class SparseSource : public ::testing::TestWithParam<bool> {};

TEST_P(SparseSource, StillRegisters) {
  // Isolated floor points have fewer than k neighbours, so they get no covariance; the scan
  // registers with farlio's defaults (point-to-point factors weighted by the spacing, line
  // pairs left out) and with the paper's (Omega = I, line pairs kept).
  Problem pb(make_pose(0.5, 0.2, 0.0, 3.0), true);
  std::size_t without = 0;
  for (const auto& p : pb.source.points) without += map::has_covariance(p) ? 0 : 1;
  EXPECT_GE(without, 20u) << "the fallback must be exercised";
  const SE3 guess = pb.truth * make_pose(0.3, -0.2, 0.1, 2.0);
  RegistrationConfig cfg;
  const bool paper = GetParam();
  cfg.skip_line_pairs = !paper;
  const double spacing_m = 0.632;
  const auto th = Thresholds::from_sigma(1.0, paper ? 1.0 : point_to_point_precision(cfg, 1e-3, spacing_m));
  const auto res = register_scan(pb.source, pb.target.view(), guess, th, cfg, kNoBudget, pb.ex);
  EXPECT_LT(trans_err(res.pose, pb.truth), 0.05);
  EXPECT_LT(rot_err_deg(res.pose, pb.truth), 0.2);
}

INSTANTIATE_TEST_SUITE_P(PaperWeighting, SparseSource, ::testing::Bool());

TEST(Gicp, PairsOfLineLikeCovariancesAreLeftOut) {
  // A map holding one line along y (a scan line on the ground seen from one place). A line-like
  // source point matched to it gives no factor with skip_line_pairs; a surface-like one does.
  exec::CpuExecutor ex(1);
  std::vector<Eigen::Vector3f> lines;
  for (int j = 0; j < 40; ++j) lines.emplace_back(10.0f, -6.0f + 0.3f * static_cast<float>(j), 0.0f);
  map::VoxelMap target(VoxelMapConfig{}, ex);
  target.insert(lines, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  std::size_t line_like = 0, valid_covs = 0;
  target.for_each_point([&](const Eigen::Vector3f&, const map::Cov3& c, bool valid) {
    valid_covs += valid ? 1 : 0;
    line_like += valid && map::classify_shape(c.matrix(), 10.0f) == map::PointShape::Line ? 1 : 0;
  });
  EXPECT_GE(valid_covs, 8u);
  EXPECT_EQ(line_like, valid_covs) << "every covariance of a lone line is line-like";
  FactorParams fp{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.1f, 0.0f, 0.0f), 4.0f, CauchyKernel{1.0f}, true};
  const map::Cov3 c = map::Cov3::from(Eigen::Matrix3f::Identity());
  const Eigen::Vector4f line_src(10.0f, 0.0f, 0.0f, map::shape_code(map::PointShape::Line));
  const Eigen::Vector4f surface_src(10.0f, 0.0f, 0.0f, map::shape_code(map::PointShape::Surface));
  FactorTerms f{};
  EXPECT_FALSE(gicp_factor(target.view(), line_src, c, fp, f));
  EXPECT_TRUE(gicp_factor(target.view(), surface_src, c, fp, f));
  fp.skip_line_pairs = false;
  EXPECT_TRUE(gicp_factor(target.view(), line_src, c, fp, f));
}

TEST(Gicp, TimeBudgetStopsIt) {
  Problem pb(make_pose(0, 0, 0, 0));
  const SE3 guess = make_pose(0.5, 0.3, 0.0, 4.0);
  const auto res =
      register_scan(pb.source, pb.target.view(), guess, Thresholds::from_sigma(1.0), RegistrationConfig{}, 0.0, pb.ex);
  EXPECT_EQ(res.iterations, 1);
  EXPECT_TRUE(res.budget_exceeded);
  EXPECT_FALSE(res.converged);
}

TEST(Gicp, NoCorrespondencesIsNotConvergence) {
  Problem pb(make_pose(0, 0, 0, 0));
  const SE3 far_away = make_pose(500.0, 0.0, 0.0, 0.0);
  const auto res = register_scan(pb.source, pb.target.view(), far_away, Thresholds::from_sigma(1.0),
                                 RegistrationConfig{}, 1.0, pb.ex);
  EXPECT_FALSE(res.converged);
  EXPECT_EQ(res.system.inliers, 0);
  EXPECT_LT(trans_err(res.pose, far_away), 1e-12);  // pose untouched
}

TEST(AdaptiveThreshold, FollowsTheRmsOfSampledDeviations) {
  ThresholdConfig cfg;
  AdaptiveThreshold th(cfg);
  EXPECT_DOUBLE_EQ(th.sigma_m(), cfg.initial_threshold_m);
  th.update(make_pose(0.1, 0, 0, 0));  // below min motion: not sampled
  EXPECT_DOUBLE_EQ(th.sigma_m(), 1.0);
  th.update(make_pose(2.0, 0, 0, 0));
  EXPECT_NEAR(th.sigma_m(), std::sqrt((1.0 + 4.0) / 2.0), 1e-12);
  // a rotation counts as its displacement at max range: 2 * 100 * sin(0.5 deg / 2)
  const double e = th.update(make_pose(0, 0, 0, 0.5));
  EXPECT_NEAR(e, 200.0 * std::sin(0.25 * M_PI / 180.0), 1e-9);
  th.update(make_pose(1000.0, 0, 0, 0));
  EXPECT_DOUBLE_EQ(th.sigma_m(), cfg.max_threshold_m);
}
