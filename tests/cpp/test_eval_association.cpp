#include <gtest/gtest.h>

#include <vector>

#include "eval_test_trajectories.hpp"
#include "farlio/core/error.hpp"
#include "farlio/eval/association.hpp"

using namespace farlio;
using namespace farlio::eval;

namespace {
constexpr std::int64_t kMs_ns = 1'000'000;

Trajectory shifted(const Trajectory& t, std::int64_t offset_ns) {
  Trajectory out;
  for (const auto& p : t) out.push_back(p.stamp_ns + offset_ns, p.pose);
  return out;
}
}  // namespace

TEST(EvalAssociation, IdenticalStampsPairEveryPoseExactly) {
  const Trajectory gt = test::smooth_curve(50);
  const AssociatedPoses a = associate(gt, gt);
  ASSERT_EQ(a.size(), gt.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.estimate_indices[k], k);
    EXPECT_EQ(a.stamps_ns[k], gt[k].stamp_ns);
    EXPECT_EQ((a.groundtruth[k].matrix() - gt[k].pose.matrix()).norm(), 0.0);
  }
}

TEST(EvalAssociation, InterpolatesGroundTruthBetweenStamps) {
  const Trajectory gt = test::smooth_curve(50);
  const Trajectory est = shifted(test::smooth_curve(49), test::kFramePeriod_ns / 2);  // midway stamps
  const AssociatedPoses a = associate(est, gt);
  ASSERT_EQ(a.size(), est.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    const SE3 expected = interpolate(gt[k].pose, gt[k + 1].pose, 0.5);
    EXPECT_LT((a.groundtruth[k].matrix() - expected.matrix()).norm(), 1e-12);
  }
  // Nearest mode with a 10 ms tolerance finds nothing 50 ms away.
  AssociationOptions nearest;
  nearest.mode = AssociationMode::kNearest;
  EXPECT_EQ(associate(est, gt, nearest).size(), 0U);
}

TEST(EvalAssociation, NearestModeRespectsTolerance) {
  const Trajectory gt = test::smooth_curve(20);
  AssociationOptions nearest;
  nearest.mode = AssociationMode::kNearest;
  nearest.max_time_diff_s = 0.01;
  const Trajectory within = shifted(gt, 9 * kMs_ns);
  const AssociatedPoses a = associate(within, gt, nearest);
  ASSERT_EQ(a.size(), gt.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ((a.groundtruth[k].matrix() - gt[k].pose.matrix()).norm(), 0.0);
  EXPECT_EQ(associate(shifted(gt, 11 * kMs_ns), gt, nearest).size(), 0U);
}

TEST(EvalAssociation, GapsAndOutsideSpanFallBackToNearest) {
  // Ground truth at 0, 100 ms, then a 2 s gap, then 2.1 s.
  Trajectory gt;
  gt.push_back(0, SE3::identity());
  gt.push_back(100 * kMs_ns, SE3::identity());
  gt.push_back(2100 * kMs_ns, SE3::identity());
  Trajectory est;
  est.push_back(-5 * kMs_ns, SE3::identity());    // before the span, within 10 ms: nearest
  est.push_back(50 * kMs_ns, SE3::identity());    // interpolated
  est.push_back(105 * kMs_ns, SE3::identity());   // inside the long gap, 5 ms from a pose: nearest
  est.push_back(1000 * kMs_ns, SE3::identity());  // inside the long gap, far from both: dropped
  est.push_back(2200 * kMs_ns, SE3::identity());  // after the span, 100 ms away: dropped
  const AssociatedPoses a = associate(est, gt);
  EXPECT_EQ(a.estimate_indices, (std::vector<std::size_t>{0, 1, 2}));
}

TEST(EvalAssociation, RejectsUnorderedTrajectories) {
  Trajectory bad;
  bad.push_back(10, SE3::identity());
  bad.push_back(5, SE3::identity());
  const Trajectory good = test::smooth_curve(5);
  EXPECT_THROW(associate(bad, good), InputError);
  EXPECT_THROW(associate(good, bad), InputError);
}

TEST(EvalAssociation, CoverageCountsScanStampsWithAnEstimate) {
  const Trajectory gt = test::smooth_curve(40);
  Trajectory est;  // every 4th frame missing: 30 of 40
  for (std::size_t k = 0; k < gt.size(); ++k) {
    if (k % 4 != 3) est.push_back(gt[k].stamp_ns + 3 * kMs_ns, gt[k].pose);
  }
  std::vector<std::int64_t> scans;
  for (const auto& p : gt) scans.push_back(p.stamp_ns);
  EXPECT_DOUBLE_EQ(coverage(est, scans, 0.01), 30.0 / 40.0);
  EXPECT_DOUBLE_EQ(coverage(est, scans, 0.002), 0.0);
  EXPECT_DOUBLE_EQ(coverage(Trajectory{}, scans, 0.01), 0.0);
}
