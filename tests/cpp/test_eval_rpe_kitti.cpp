#include <gtest/gtest.h>

#include <random>

#include "eval_test_trajectories.hpp"
#include "farlio/eval/angles.hpp"
#include "farlio/eval/rpe_kitti.hpp"

using namespace farlio;
using namespace farlio::eval;

namespace {
// 0.5 m per frame is exact in binary, so path lengths are exact and segments end exactly at L.
constexpr double kStep_m = 0.5;
constexpr double kYawPerFrame_rad = 1e-4;
}  // namespace

TEST(EvalKittiRpe, IdenticalTrajectoriesGiveZero) {
  const auto gt = test::poses_of(test::smooth_curve(3000));
  const KittiRpeResult r = compute_kitti_rpe(gt, gt);
  EXPECT_GT(r.segment_count, 0U);
  EXPECT_LT(r.translation_pct, 1e-9);
  EXPECT_LT(r.rotation_deg_per_100m, 1e-6);
}

TEST(EvalKittiRpe, ScaledMotionGivesExactlyOnePercent) {
  const Trajectory line = test::straight_line(2001, kStep_m);  // 1000 m: the KITTI lengths apply
  const Trajectory est =
      test::with_modified_increments(line, [](const SE3& d) { return SE3(d.quaternion(), 1.01 * d.translation()); });
  const KittiRpeResult r = compute_kitti_rpe(test::poses_of(est), test::poses_of(line));
  EXPECT_EQ(r.segment_lengths_m, kitti_segment_lengths_m());
  EXPECT_NEAR(r.translation_pct, 1.0, 1e-9);
  EXPECT_LT(r.rotation_deg_per_100m, 1e-9);
  // Segment count: first frames i with 0.5 i + L <= 1000, summed over L = 100..800.
  std::size_t expected = 0;
  for (double L = 100.0; L <= 800.0; L += 100.0) expected += static_cast<std::size_t>((1000.0 - L) / kStep_m) + 1;
  EXPECT_EQ(r.segment_count, expected);
  for (const auto& per : r.per_length) EXPECT_NEAR(per.translation_pct, 1.0, 1e-9);
}

TEST(EvalKittiRpe, YawDriftGivesItsRatePerMetre) {
  const Trajectory line = test::straight_line(1001, kStep_m);  // 500 m: short lengths
  const Trajectory est = test::with_modified_increments(line, [](const SE3& d) {
    return SE3(d.rotation() * Eigen::AngleAxisd(kYawPerFrame_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
               d.translation());
  });
  const KittiRpeResult r = compute_kitti_rpe(test::poses_of(est), test::poses_of(line));
  EXPECT_EQ(r.segment_lengths_m, short_segment_lengths_m());
  // A segment of L metres spans L / step frames, each adding kYawPerFrame of yaw.
  const double expected_deg_per_100m = kYawPerFrame_rad / kStep_m * kDegreesPerRadian * 100.0;
  EXPECT_NEAR(r.rotation_deg_per_100m, expected_deg_per_100m, 1e-9 * expected_deg_per_100m);
  EXPECT_GT(r.translation_pct, 0.0);
}

TEST(EvalKittiRpe, MatchesBruteForceOnRandomWalk) {
  // Random walk with repeated poses (zero steps); step_frames = 3, explicit lengths.
  std::mt19937 rng(31);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_int_distribution<int> repeat(0, 4);
  std::vector<SE3> gt, est;
  SE3 g, e;
  for (int k = 0; k < 400; ++k) {
    gt.push_back(g);
    est.push_back(e);
    if (repeat(rng) == 0) continue;
    Vec6d xi;
    for (int c = 0; c < 6; ++c) xi[c] = n(rng);
    xi.tail<3>() *= 0.05;
    g = g * SE3::exp(xi);
    Vec6d noise;
    for (int c = 0; c < 6; ++c) noise[c] = 0.01 * n(rng);
    e = e * SE3::exp(xi + noise);
  }
  KittiRpeOptions options;
  options.step_frames = 3;
  options.segment_lengths_m = {5.0, 20.0, 60.0};
  const KittiRpeResult r = compute_kitti_rpe(est, gt, options);

  // Brute force: path length by direct summation from i, first j reaching L by linear search.
  double t_sum = 0.0, r_sum = 0.0;
  std::size_t count = 0;
  for (const double L : options.segment_lengths_m) {
    for (std::size_t i = 0; i < gt.size(); i += options.step_frames) {
      double d = 0.0;
      std::size_t j = i;
      while (j + 1 < gt.size() && d < L) {
        d += (gt[j + 1].translation() - gt[j].translation()).norm();
        ++j;
      }
      if (d < L) continue;
      const Mat4d E =
          (gt[i].matrix().inverse() * gt[j].matrix()).inverse() * (est[i].matrix().inverse() * est[j].matrix());
      t_sum += E.block<3, 1>(0, 3).norm() / L;
      const double c = std::clamp(0.5 * (E.block<3, 3>(0, 0).trace() - 1.0), -1.0, 1.0);
      r_sum += std::acos(c) / L;
      ++count;
    }
  }
  ASSERT_GT(count, 0U);
  EXPECT_EQ(r.segment_count, count);
  EXPECT_NEAR(r.translation_pct, 100.0 * t_sum / static_cast<double>(count), 1e-9);
  EXPECT_NEAR(r.rotation_deg_per_100m, 100.0 * kDegreesPerRadian * r_sum / static_cast<double>(count), 1e-6);
}

TEST(EvalKittiRpe, TooShortPathGivesNoSegments) {
  const auto line = test::poses_of(test::straight_line(100, kStep_m));  // 49.5 m < 80 m
  KittiRpeOptions options;
  options.segment_lengths_m = {80.0};
  const KittiRpeResult r = compute_kitti_rpe(line, line, options);
  EXPECT_EQ(r.segment_count, 0U);
  EXPECT_EQ(r.translation_pct, 0.0);
}
