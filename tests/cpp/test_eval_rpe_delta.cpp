#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval_test_trajectories.hpp"
#include "farlio/core/error.hpp"
#include "farlio/eval/rpe_delta.hpp"

using namespace farlio;
using namespace farlio::eval;

namespace {

/// Random walk with some repeated poses, so equal path lengths (ties) occur.
std::vector<SE3> random_walk(std::mt19937& rng, std::size_t count) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_int_distribution<int> repeat(0, 3);
  std::vector<SE3> poses;
  SE3 pose;
  for (std::size_t k = 0; k < count; ++k) {
    poses.push_back(pose);
    if (repeat(rng) == 0) continue;
    Vec6d xi;
    for (int c = 0; c < 6; ++c) xi[c] = n(rng);
    xi.tail<3>() *= 0.1;
    pose = pose * SE3::exp(xi);
  }
  return poses;
}

double path_between(const std::vector<SE3>& p, std::size_t a, std::size_t b) {
  double d = 0.0;
  for (std::size_t k = a; k < b; ++k) d += (p[k + 1].translation() - p[k].translation()).norm();
  return d;
}

/// Pair selection written directly from the definitions, without cumulative sums or searches.
std::vector<IndexPair> brute_force_pairs(const std::vector<SE3>& p, const DeltaRpeOptions& o) {
  std::vector<IndexPair> pairs;
  const std::size_t n = p.size();
  if (o.unit == DeltaUnit::kFrames) {
    const auto delta = static_cast<std::size_t>(o.delta);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        if (j - i == delta && (o.all_pairs || i % delta == 0)) pairs.emplace_back(i, j);
      }
    }
    return pairs;
  }
  if (o.all_pairs) {
    for (std::size_t i = 0; i + 1 < n; ++i) {
      std::size_t best = i + 1;
      double best_miss = std::abs(path_between(p, i, i + 1) - o.delta);
      for (std::size_t k = i + 2; k < n; ++k) {
        const double miss = std::abs(path_between(p, i, k) - o.delta);
        if (miss < best_miss) {
          best = k;
          best_miss = miss;
        }
      }
      if (best_miss <= o.rel_delta_tol * o.delta) pairs.emplace_back(i, best);
    }
    return pairs;
  }
  std::size_t last = 0;
  for (std::size_t k = 1; k < n; ++k) {
    if (path_between(p, last, k) >= o.delta) {
      pairs.emplace_back(last, k);
      last = k;
    }
  }
  return pairs;
}

}  // namespace

TEST(EvalDeltaRpe, PairSelectionMatchesBruteForce) {
  std::mt19937 rng(41);
  const std::vector<SE3> poses = random_walk(rng, 120);
  for (const bool all : {false, true}) {
    for (const double frames : {1.0, 3.0, 7.0}) {
      DeltaRpeOptions o{.delta = frames, .unit = DeltaUnit::kFrames, .all_pairs = all};
      EXPECT_EQ(select_rpe_pairs(poses, o), brute_force_pairs(poses, o)) << frames << " frames, all " << all;
    }
    for (const double metres : {0.7, 2.0, 5.0, 10.0}) {
      DeltaRpeOptions o{.delta = metres, .unit = DeltaUnit::kMeters, .all_pairs = all};
      const auto pairs = select_rpe_pairs(poses, o);
      EXPECT_FALSE(pairs.empty());
      EXPECT_EQ(pairs, brute_force_pairs(poses, o)) << metres << " m, all " << all;
    }
  }
}

TEST(EvalDeltaRpe, ErrorIsTheRelativeTransformOfRelativeMotions) {
  std::mt19937 rng(42);
  const std::vector<SE3> gt = random_walk(rng, 60), est = random_walk(rng, 60);
  const DeltaRpeOptions o{.delta = 4.0, .unit = DeltaUnit::kFrames, .all_pairs = true};
  const DeltaRpeResult r = compute_delta_rpe(est, gt, o);
  ASSERT_EQ(r.pairs.size(), 56U);
  double sum_sq = 0.0;
  for (std::size_t n = 0; n < r.pairs.size(); ++n) {
    const auto [i, j] = r.pairs[n];
    const Mat4d E =
        (gt[i].matrix().inverse() * gt[j].matrix()).inverse() * (est[i].matrix().inverse() * est[j].matrix());
    const double expected_m = E.block<3, 1>(0, 3).norm();
    EXPECT_NEAR(r.translation_errors_m[n], expected_m, 1e-9);
    sum_sq += E.block<3, 1>(0, 3).squaredNorm();
  }
  EXPECT_NEAR(r.translation_m.rmse, std::sqrt(sum_sq / 56.0), 1e-9);
}

TEST(EvalDeltaRpe, IdenticalOrRigidlyMovedEstimateGivesZero) {
  std::mt19937 rng(43);
  const std::vector<SE3> gt = random_walk(rng, 80);
  const SE3 offset = test::random_se3(rng, 10.0);
  std::vector<SE3> moved;
  for (const auto& p : gt) moved.push_back(offset * p);
  for (const auto& est : {gt, moved}) {
    const DeltaRpeResult r = compute_delta_rpe(est, gt, {.delta = 2.0, .unit = DeltaUnit::kMeters});
    EXPECT_GT(r.translation_m.count, 0U);
    EXPECT_LT(r.translation_m.max, 1e-9);
    EXPECT_LT(r.rotation_deg.max, 1e-6);
  }
}

TEST(EvalDeltaRpe, PairsComeFromTheChosenTrajectory) {
  // The estimate moves twice as far per frame: 1 m of estimate path is half a frame of ground truth.
  const Trajectory gt = test::straight_line(20, 1.0);
  const Trajectory est = test::straight_line(20, 2.0);
  DeltaRpeOptions o{.delta = 2.0, .unit = DeltaUnit::kMeters};
  EXPECT_EQ(compute_delta_rpe(test::poses_of(est), test::poses_of(gt), o).pairs.front(), IndexPair(0, 2));
  o.pairs_from_groundtruth = false;
  EXPECT_EQ(compute_delta_rpe(test::poses_of(est), test::poses_of(gt), o).pairs.front(), IndexPair(0, 1));
}

TEST(EvalDeltaRpe, RejectsBadDelta) {
  const std::vector<SE3> poses(5);
  EXPECT_THROW(select_rpe_pairs(poses, {.delta = 0.0}), InputError);
  EXPECT_THROW(select_rpe_pairs(poses, {.delta = 1.5, .unit = DeltaUnit::kFrames}), InputError);
}
