#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "eval_test_trajectories.hpp"
#include "farlio/core/error.hpp"
#include "farlio/eval/alignment.hpp"
#include "farlio/eval/angles.hpp"
#include "farlio/eval/ape.hpp"
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

// ---- align_poses: estimate = rigid offset * (ground truth with small pose errors) ----------------

enum class Shape { kStraight, kNearlyStraight, kCurved, kStationary };

constexpr std::size_t kPoses = 200;
constexpr double kStepM = 0.5;                  // straight runs: metres per pose
constexpr double kWiggleM = 0.002;              // nearly straight: lateral sine amplitude
constexpr double kWigglePeriodPoses = 37.0;     // ... and its period
constexpr double kPositionNoiseM = 0.01;        // per axis
constexpr double kRotationErrorRmsDeg = 0.1;    // RMS angle of the per-pose rotation error
constexpr double kStationaryYawRateRad = 0.02;  // per pose, turning on the spot
constexpr double kMaxAlignedRotationRmseDeg = 1.0;
// the aligned rotation RMSE may differ from the true one by what one fitted rotation absorbs
constexpr double kRotationRmseToleranceDeg = 0.05;

std::string shape_name(Shape s) {
  switch (s) {
    case Shape::kStraight: return "Straight";
    case Shape::kNearlyStraight: return "NearlyStraight";
    case Shape::kCurved: return "Curved";
    case Shape::kStationary: return "Stationary";
  }
  return "";
}

std::vector<SE3> ground_truth(Shape shape) {
  std::vector<SE3> gt;
  if (shape == Shape::kCurved) return test::poses_of(test::smooth_curve(kPoses));
  for (std::size_t k = 0; k < kPoses; ++k) {
    const double i = static_cast<double>(k);
    if (shape == Shape::kStationary) {
      gt.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(kStationaryYawRateRad * i, Eigen::Vector3d::UnitZ())),
                      Eigen::Vector3d(1.0, 2.0, 3.0));
      continue;
    }
    const double lateral =
        shape == Shape::kNearlyStraight ? kWiggleM * std::sin(2.0 * M_PI * i / kWigglePeriodPoses) : 0;
    gt.emplace_back(Eigen::Quaterniond::Identity(), Eigen::Vector3d(kStepM * i, lateral, 0.0));
  }
  return gt;
}

struct NoisyEstimate {
  std::vector<SE3> poses;
  double true_rotation_rmse_deg = 0.0;  // of the per-pose errors before the rigid offset
};

/// offset * (R_k dR_k, t_k + noise): every pose has a rotation error dR_k and a position error.
NoisyEstimate noisy_estimate(const std::vector<SE3>& gt, const SE3& offset, std::mt19937& rng) {
  std::normal_distribution<double> position(0.0, kPositionNoiseM);
  std::normal_distribution<double> angle(0.0, kRotationErrorRmsDeg / kDegreesPerRadian / std::sqrt(3.0));
  NoisyEstimate e;
  double sum_sq = 0.0;
  for (const SE3& p : gt) {
    const Eigen::Vector3d phi(angle(rng), angle(rng), angle(rng));
    sum_sq += phi.squaredNorm();
    const Eigen::Vector3d noise(position(rng), position(rng), position(rng));
    e.poses.push_back(offset * SE3(p.rotation() * so3_exp(phi), p.translation() + noise));
  }
  e.true_rotation_rmse_deg = std::sqrt(sum_sq / static_cast<double>(gt.size())) * kDegreesPerRadian;
  return e;
}

class AlignPoses : public ::testing::TestWithParam<std::tuple<Shape, unsigned>> {};

TEST_P(AlignPoses, RotationErrorIsTheTrueOneOnEveryShape) {
  const auto [shape, seed] = GetParam();
  std::mt19937 rng(seed);
  const SE3 offset = test::random_se3(rng, 20.0);
  const SE3 placement = test::random_se3(rng, 5.0);  // the ground truth in a general direction
  std::vector<SE3> gt = ground_truth(shape);
  for (SE3& p : gt) p = placement * p;
  const NoisyEstimate est = noisy_estimate(gt, offset, rng);

  const ApeResult r = compute_ape(est.poses, gt);
  const AlignmentMethod expected = shape == Shape::kCurved       ? AlignmentMethod::kUmeyama
                                   : shape == Shape::kStationary ? AlignmentMethod::kOrientation
                                                                 : AlignmentMethod::kUmeyamaOrientation;
  EXPECT_EQ(r.alignment.method, expected);
  EXPECT_LT(r.rotation_deg.rmse, kMaxAlignedRotationRmseDeg);
  EXPECT_NEAR(r.rotation_deg.rmse, est.true_rotation_rmse_deg, kRotationRmseToleranceDeg);
  // the translation error is the position noise (sigma sqrt(3)), within sampling error
  EXPECT_NEAR(r.translation_m.rmse, kPositionNoiseM * std::sqrt(3.0), 0.2 * kPositionNoiseM * std::sqrt(3.0));

  std::vector<Eigen::Vector3d> est_positions, gt_positions;
  for (std::size_t k = 0; k < gt.size(); ++k) {
    est_positions.push_back(est.poses[k].translation());
    gt_positions.push_back(gt[k].translation());
  }
  const Alignment umeyama = umeyama_align(est_positions, gt_positions);
  if (shape == Shape::kCurved) {  // not degenerate: exactly Umeyama
    EXPECT_LT((r.alignment.transform.matrix() - umeyama.transform.matrix()).norm(), kExactTol);
  }
  if (shape == Shape::kStraight) {
    // exactly collinear ground truth: turning about the line leaves every position residual as it was
    for (std::size_t k = 0; k < gt.size(); ++k) {
      EXPECT_NEAR(r.translation_errors_m[k], (gt_positions[k] - umeyama.apply(est_positions[k])).norm(), 1e-9);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(ShapesAndSeeds, AlignPoses,
                         ::testing::Combine(::testing::Values(Shape::kStraight, Shape::kNearlyStraight, Shape::kCurved,
                                                              Shape::kStationary),
                                            ::testing::Values(1U, 2U, 3U)),
                         [](const auto& test_info) {
                           return shape_name(std::get<0>(test_info.param)) + "Seed" +
                                  std::to_string(std::get<1>(test_info.param));
                         });

TEST(EvalAlignment, CollinearSim3KeepsTheScaleAlongTheLine) {
  constexpr double kScale = 1.25;
  std::mt19937 rng(31);
  const SE3 offset = test::random_se3(rng, 10.0);
  const std::vector<SE3> gt = ground_truth(Shape::kStraight);
  std::vector<SE3> est;
  for (const SE3& p : gt) est.push_back(offset * SE3(p.quaternion(), kScale * p.translation()));
  const Alignment a = align_poses(est, gt, /*with_scale=*/true);
  EXPECT_EQ(a.method, AlignmentMethod::kUmeyamaOrientation);
  EXPECT_NEAR(a.scale, 1.0 / kScale, 1e-12);
  for (std::size_t k = 0; k < gt.size(); ++k) {
    EXPECT_LT((a.apply(est[k]).matrix() - gt[k].matrix()).norm(), 1e-9);
  }
}

TEST(EvalAlignment, RejectsMismatchedSizes) {
  const std::vector<Eigen::Vector3d> a(3, Eigen::Vector3d::Zero()), b(4, Eigen::Vector3d::Zero());
  EXPECT_THROW(umeyama_align(a, b), InputError);
  EXPECT_THROW(umeyama_align(std::vector<Eigen::Vector3d>{}, std::vector<Eigen::Vector3d>{}), InputError);
  const std::vector<SE3> p(3), q(4);
  EXPECT_THROW(align_poses(p, q), InputError);
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
