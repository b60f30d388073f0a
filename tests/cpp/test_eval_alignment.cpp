#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "eval_test_trajectories.hpp"
#include "farlio/core/error.hpp"
#include "farlio/eval/alignment.hpp"
#include "farlio/eval/error_stats.hpp"

using namespace farlio;
using namespace farlio::eval;

namespace {
constexpr double kExactTol = 1e-10;

std::vector<Eigen::Vector3d> random_points(std::mt19937& rng, std::size_t count) {
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t k = 0; k < count; ++k) pts.emplace_back(u(rng), u(rng), u(rng));
  return pts;
}
}  // namespace

TEST(EvalAlignment, UmeyamaRecoversRandomSe3FromNoiseFreePoints) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const SE3 truth = test::random_se3(rng, 30.0);
    const auto source = random_points(rng, 50);
    std::vector<Eigen::Vector3d> target;
    for (const auto& p : source) target.push_back(truth * p);
    const Alignment a = umeyama_align(source, target);
    EXPECT_LT((a.transform.matrix() - truth.matrix()).norm(), kExactTol);
    EXPECT_DOUBLE_EQ(a.scale, 1.0);
    EXPECT_FALSE(a.rank_deficient);
  }
}

TEST(EvalAlignment, PlanarPointsStillGiveAProperRotation) {
  // Rank-2 covariance: the det(U)det(V) correction must avoid returning a reflection.
  std::mt19937 rng(12);
  auto source = random_points(rng, 30);
  for (auto& p : source) p.z() = 0.0;
  const SE3 truth = test::random_se3(rng, 5.0);
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(truth * p);
  const Alignment a = umeyama_align(source, target);
  EXPECT_LT((a.transform.matrix() - truth.matrix()).norm(), kExactTol);
  EXPECT_NEAR(a.transform.rotation().determinant(), 1.0, 1e-12);
}

TEST(EvalAlignment, Sim3RecoversScale) {
  std::mt19937 rng(13);
  const SE3 truth = test::random_se3(rng, 10.0);
  constexpr double kScale = 2.7;
  const auto source = random_points(rng, 40);
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(truth.rotation() * (kScale * p) + truth.translation());
  const Alignment a = umeyama_align(source, target, /*with_scale=*/true);
  EXPECT_NEAR(a.scale, kScale, 1e-12);
  EXPECT_LT((a.transform.matrix() - truth.matrix()).norm(), kExactTol);
  for (std::size_t k = 0; k < source.size(); ++k) EXPECT_LT((a.apply(source[k]) - target[k]).norm(), kExactTol);
}

TEST(EvalAlignment, CollinearPointsAreFlaggedButStillFit) {
  std::vector<Eigen::Vector3d> source, target;
  const Eigen::Vector3d offset(1.0, 2.0, 3.0);
  for (int k = 0; k < 10; ++k) {
    source.emplace_back(k, 0.0, 0.0);
    target.push_back(Eigen::Vector3d(0.0, k, 0.0) + offset);
  }
  const Alignment a = umeyama_align(source, target);
  EXPECT_TRUE(a.rank_deficient);
  for (std::size_t k = 0; k < source.size(); ++k) EXPECT_LT((a.apply(source[k]) - target[k]).norm(), kExactTol);
}

TEST(EvalAlignment, RejectsMismatchedSizes) {
  const std::vector<Eigen::Vector3d> a(3, Eigen::Vector3d::Zero()), b(4, Eigen::Vector3d::Zero());
  EXPECT_THROW(umeyama_align(a, b), InputError);
  EXPECT_THROW(umeyama_align(std::vector<Eigen::Vector3d>{}, std::vector<Eigen::Vector3d>{}), InputError);
}

TEST(EvalErrorStats, KnownValues) {
  const std::vector<double> e{4.0, 1.0, 3.0, 2.0};
  const ErrorStats s = compute_stats(e);
  EXPECT_EQ(s.count, 4U);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  const std::vector<double> odd{5.0, 1.0, 3.0};
  EXPECT_DOUBLE_EQ(compute_stats(odd).median, 3.0);
  EXPECT_EQ(compute_stats(std::vector<double>{}).count, 0U);
}
