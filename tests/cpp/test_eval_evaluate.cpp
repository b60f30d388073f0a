#include <gtest/gtest.h>

#include "eval_test_trajectories.hpp"
#include "farlio/core/error.hpp"
#include "farlio/eval/metrics.hpp"

using namespace farlio;
using namespace farlio::eval;

TEST(EvalEvaluate, IdenticalTrajectoriesGiveZeroEverywhere) {
  const Trajectory gt = test::smooth_curve(3000);
  const EvaluationResult r = evaluate(gt, gt);
  EXPECT_EQ(r.associated_poses, gt.size());
  EXPECT_DOUBLE_EQ(r.coverage, 1.0);
  EXPECT_NEAR(r.groundtruth_path_length_m, gt.path_length_m(), 1e-9);
  EXPECT_LT(r.ape.translation_m.max, 1e-9);
  EXPECT_EQ(r.ape.translation_raw_m.max, 0.0);
  EXPECT_LT(r.ape.rotation_deg.max, 1e-6);
  EXPECT_GT(r.kitti_rpe.segment_count, 0U);
  EXPECT_LT(r.kitti_rpe.translation_pct, 1e-9);
  EXPECT_LT(r.kitti_rpe.rotation_deg_per_100m, 1e-6);
  EXPECT_EQ(r.rpe.translation_m.count, gt.size() - 1);
  EXPECT_LT(r.rpe.translation_m.max, 1e-9);
  EXPECT_EQ(r.ape.translation_errors_m.size(), gt.size());
  EXPECT_EQ(r.ape.aligned_estimate.size(), gt.size());
}

TEST(EvalEvaluate, SparseEstimateAgainstDenseGroundTruth) {
  // Ground truth at 10 Hz, estimate at every other frame shifted by a constant offset: APE after
  // alignment is 0, the raw APE is the offset, and coverage relative to the scan stamps is 1.
  const Trajectory gt = test::smooth_curve(1000);
  Trajectory est;
  EvalOptions options;
  const Eigen::Vector3d offset_m(0.0, 6.0, 8.0);
  for (std::size_t k = 0; k < gt.size(); k += 2) {
    est.push_back(gt[k].stamp_ns, SE3(Eigen::Quaterniond::Identity(), offset_m) * gt[k].pose);
    options.scan_stamps_ns.push_back(gt[k].stamp_ns);
  }
  const EvaluationResult r = evaluate(est, gt, options);
  EXPECT_EQ(r.associated_poses, est.size());
  EXPECT_DOUBLE_EQ(r.coverage, 1.0);
  EXPECT_LT(r.ape.translation_m.rmse, 1e-9);
  EXPECT_NEAR(r.ape.translation_raw_m.rmse, 10.0, 1e-9);

  options.scan_stamps_ns.clear();  // now relative to every ground-truth stamp
  EXPECT_DOUBLE_EQ(evaluate(est, gt, options).coverage, 0.5);
}

TEST(EvalEvaluate, TooFewAssociationsThrow) {
  const Trajectory gt = test::smooth_curve(10);
  Trajectory far_away;
  for (int k = 0; k < 10; ++k) far_away.push_back(1'000'000'000'000 + k * test::kFramePeriod_ns, SE3::identity());
  EXPECT_THROW(evaluate(far_away, gt), InputError);
}
