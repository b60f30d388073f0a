#include <gtest/gtest.h>

#include <random>

#include "farlio/core/se3.hpp"
#include "farlio/core/trajectory.hpp"

using namespace farlio;

namespace {
Vec6d random_twist(std::mt19937& rng, double scale_rot) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec6d xi;
  for (int i = 0; i < 6; ++i) xi[i] = n(rng);
  xi.tail<3>() *= scale_rot;
  return xi;
}
}  // namespace

TEST(SE3, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  for (double scale : {1e-10, 1e-5, 0.1, 1.0, 2.5}) {
    for (int k = 0; k < 50; ++k) {
      Vec6d xi = random_twist(rng, scale);
      if (xi.tail<3>().norm() > 3.1) continue;  // log returns |phi| <= pi
      const Vec6d back = SE3::exp(xi).log();
      EXPECT_LT((back - xi).norm(), 1e-9) << "scale " << scale;
    }
  }
}

TEST(SE3, ExpMatchesMatrixExponential) {
  // exp of the 4x4 twist matrix computed by a truncated power series.
  std::mt19937 rng(2);
  const Vec6d xi = random_twist(rng, 0.7);
  Mat4d X = Mat4d::Zero();
  X.block<3, 3>(0, 0) = hat(xi.tail<3>());
  X.block<3, 1>(0, 3) = xi.head<3>();
  Mat4d term = Mat4d::Identity(), sum = Mat4d::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * X / static_cast<double>(k);
    sum += term;
  }
  EXPECT_LT((SE3::exp(xi).matrix() - sum).norm(), 1e-12);
}

TEST(SE3, ComposeInverseAndAct) {
  std::mt19937 rng(3);
  const SE3 a = SE3::exp(random_twist(rng, 1.0)), b = SE3::exp(random_twist(rng, 1.0));
  EXPECT_LT(((a * b).matrix() - a.matrix() * b.matrix()).norm(), 1e-12);
  EXPECT_LT(((a * a.inverse()).matrix() - Mat4d::Identity()).norm(), 1e-12);
  const Eigen::Vector3d p(1, -2, 3);
  EXPECT_LT(((a * p) - (a.matrix() * p.homogeneous()).head<3>()).norm(), 1e-12);
}

TEST(SE3, AngleAndLeftJacobianInverse) {
  const SE3 r(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())), Eigen::Vector3d::Zero());
  EXPECT_NEAR(r.angle_rad(), 0.3, 1e-12);
  const Eigen::Vector3d phi(0.4, -0.2, 0.9);
  EXPECT_LT((so3_left_jacobian(phi) * so3_left_jacobian_inverse(phi) - Mat3d::Identity()).norm(), 1e-12);
}

TEST(Trajectory, InterpolatesAndRefusesToExtrapolate) {
  Trajectory t;
  t.push_back(0, SE3::identity());
  Vec6d xi = Vec6d::Zero();
  xi << 2.0, 0, 0, 0, 0, 1.0;
  t.push_back(1'000'000'000, SE3::exp(xi));
  const auto mid = t.interpolate_at(500'000'000);
  ASSERT_TRUE(mid.has_value());
  EXPECT_LT((mid->log() - 0.5 * xi).norm(), 1e-12);
  EXPECT_FALSE(t.interpolate_at(-1).has_value());
  EXPECT_FALSE(t.interpolate_at(1'000'000'001).has_value());
  EXPECT_TRUE(t.is_time_ordered());
  EXPECT_NEAR(t.path_length_m(), SE3::exp(xi).translation().norm(), 1e-12);
}

TEST(Trajectory, BetweenKeepsTheStretchWithItsBounds) {
  Trajectory t;
  for (std::int64_t k = 0; k < 10; ++k)
    t.push_back(k * 100, SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(static_cast<double>(k), 0, 0)));
  const Trajectory s = t.between(200, 500);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0].stamp_ns, 200);
  EXPECT_EQ(s[3].stamp_ns, 500);
  EXPECT_EQ(s[3].pose.translation().x(), 5.0);
  EXPECT_TRUE(t.between(1000, 2000).empty());
}
