#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval_test_trajectories.hpp"
#include "farlio/core/error.hpp"
#include "farlio/eval/ape.hpp"

using namespace farlio;
using namespace farlio::eval;

TEST(EvalApe, IdenticalTrajectoriesGiveZero) {
  const auto gt = test::poses_of(test::smooth_curve(300));
  const ApeResult r = compute_ape(gt, gt);
  EXPECT_EQ(r.translation_m.count, gt.size());
  EXPECT_LT(r.translation_m.max, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-6);
  EXPECT_EQ(r.translation_raw_m.max, 0.0);
  EXPECT_EQ(r.rotation_raw_deg.max, 0.0);
}

TEST(EvalApe, RigidOffsetIsRemovedByAlignmentButNotInRawFrame) {
  const auto gt = test::poses_of(test::smooth_curve(300));
  std::mt19937 rng(21);
  // Pure translation offset: the raw error of every pose is exactly |offset|.
  const Eigen::Vector3d offset_m(3.0, -4.0, 12.0);  // norm 13
  std::vector<SE3> shifted;
  for (const auto& p : gt) shifted.push_back(SE3(Eigen::Quaterniond::Identity(), offset_m) * p);
  const ApeResult r = compute_ape(shifted, gt);
  EXPECT_LT(r.translation_m.rmse, 1e-9);
  EXPECT_NEAR(r.translation_raw_m.rmse, 13.0, 1e-9);
  EXPECT_NEAR(r.translation_raw_m.mean, 13.0, 1e-9);
  EXPECT_NEAR(r.translation_raw_m.max, 13.0, 1e-9);
  EXPECT_LT(r.rotation_raw_deg.max, 1e-6);

  // General rigid offset (rotation too): aligned errors vanish, the raw rotation error is its angle.
  const SE3 offset = test::random_se3(rng, 20.0);
  std::vector<SE3> moved;
  for (const auto& p : gt) moved.push_back(offset * p);
  const ApeResult m = compute_ape(moved, gt);
  EXPECT_LT(m.translation_m.max, 1e-9);
  EXPECT_LT(m.rotation_deg.max, 1e-6);
  EXPECT_LT((m.alignment.transform.matrix() - offset.inverse().matrix()).norm(), 1e-9);
  // R_gt^T R_offset R_gt has the angle of R_offset for every pose.
  EXPECT_NEAR(m.rotation_raw_deg.mean, offset.angle_rad() * 180.0 / M_PI, 1e-8);
}

TEST(EvalApe, PositionNoiseGivesSigmaSqrt3) {
  const auto gt = test::poses_of(test::smooth_curve(20000, 200.0));
  constexpr double kSigma_m = 0.05;
  std::mt19937 rng(22);
  std::normal_distribution<double> n(0.0, kSigma_m);
  std::vector<SE3> noisy;
  for (const auto& p : gt)
    noisy.push_back(SE3(p.quaternion(), p.translation() + Eigen::Vector3d(n(rng), n(rng), n(rng))));
  const ApeResult r = compute_ape(noisy, gt);
  // E|e|^2 = 3 sigma^2; with 20000 samples the RMSE is within ~0.5 % of sigma*sqrt(3).
  EXPECT_NEAR(r.translation_m.rmse, kSigma_m * std::sqrt(3.0), 0.02 * kSigma_m * std::sqrt(3.0));
  // Alignment only absorbs 6 degrees of freedom: the fit never increases the error.
  EXPECT_LE(r.translation_m.rmse, r.translation_raw_m.rmse);
}

TEST(EvalApe, Sim3AlignmentRemovesScale) {
  const auto gt = test::poses_of(test::smooth_curve(500));
  constexpr double kScale = 0.8;
  std::vector<SE3> scaled;
  for (const auto& p : gt) scaled.push_back(SE3(p.quaternion(), kScale * p.translation()));
  EXPECT_GT(compute_ape(scaled, gt).translation_m.rmse, 1.0);
  const ApeResult r = compute_ape(scaled, gt, /*align_with_scale=*/true);
  EXPECT_NEAR(r.alignment.scale, 1.0 / kScale, 1e-9);
  EXPECT_LT(r.translation_m.max, 1e-8);
}

namespace {
SE3 rotation_about(const Eigen::Vector3d& axis, double angle_rad) {
  return SE3(Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized())), Eigen::Vector3d::Zero());
}
}  // namespace

TEST(EvalApe, AtTheOriginAWholeTrajectoryRotatedHasNoError) {
  // a frame turned as a whole (a map levelled 0.5 deg off, shifted): no drift from the start
  const auto gt = test::poses_of(test::smooth_curve(300));
  const SE3 frame = SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(4.0, -2.0, 1.0)) *
                    rotation_about(Eigen::Vector3d::UnitX(), 0.5 * M_PI / 180.0);
  std::vector<SE3> turned;
  for (const auto& p : gt) turned.push_back(frame * p);
  const ApeResult r = compute_ape(turned, gt, false, kDefaultMinSpreadToResidual, ApeAlignment::kOrigin);
  EXPECT_EQ(r.alignment.method, AlignmentMethod::kOrigin);
  EXPECT_LT(r.translation_m.max, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-6);
}

TEST(EvalApe, AtTheOriginAHeadingDriftGivesItsRmsAndAConstantRollAfterTheFirstPoseShows) {
  const auto gt = test::poses_of(test::smooth_curve(21));
  // each body 0.01 deg more in heading than the truth's, about its own z
  constexpr double kRate_deg = 0.01;
  std::vector<SE3> drifting, rolled;
  for (std::size_t k = 0; k < gt.size(); ++k) {
    drifting.push_back(gt[k] * rotation_about(Eigen::Vector3d::UnitZ(), kRate_deg * k * M_PI / 180.0));
    rolled.push_back(k == 0 ? gt[k] : gt[k] * rotation_about(Eigen::Vector3d::UnitX(), 0.2 * M_PI / 180.0));
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < gt.size(); ++k) sum += std::pow(kRate_deg * k, 2);
  const ApeResult d = compute_ape(drifting, gt, false, kDefaultMinSpreadToResidual, ApeAlignment::kOrigin);
  EXPECT_NEAR(d.rotation_deg.rmse, std::sqrt(sum / gt.size()), 1e-7);
  EXPECT_LT(d.translation_m.max, 1e-9);  // the bodies turned in place
  // the same roll of every body after the first: sqrt(20 / 21) 0.2 deg
  const ApeResult r = compute_ape(rolled, gt, false, kDefaultMinSpreadToResidual, ApeAlignment::kOrigin);
  EXPECT_NEAR(r.rotation_deg.rmse, std::sqrt(20.0 / 21.0) * 0.2, 1e-7);
}

TEST(EvalApe, AnOriginAlignmentWithAScaleIsAnInputError) {
  const auto gt = test::poses_of(test::smooth_curve(10));
  EXPECT_THROW(compute_ape(gt, gt, /*align_with_scale=*/true, kDefaultMinSpreadToResidual, ApeAlignment::kOrigin),
               InputError);
}
