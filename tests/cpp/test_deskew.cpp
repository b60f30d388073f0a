// Motion undistortion: the float SE(3) exponential and the per-point correction.
#include <gtest/gtest.h>

#include <random>

#include "farlio/core/se3.hpp"
#include "farlio/deskew/scan_motion.hpp"

using namespace farlio;
using namespace farlio::deskew;

TEST(Deskew, FloatExpMatchesDoubleExp) {
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double scale : {1e-6, 1e-3, 0.3, 2.0}) {
    Vec6d xi;
    for (int i = 0; i < 6; ++i) xi[i] = n(rng) * scale;
    Eigen::Matrix3f R;
    Eigen::Vector3f t;
    se3_exp(xi.cast<float>(), R, t);
    const SE3 ref = SE3::exp(xi);
    EXPECT_LT((R.cast<double>() - ref.rotation()).norm(), 1e-5);
    EXPECT_LT((t.cast<double>() - ref.translation()).norm(), 1e-5 * std::max(1.0, ref.translation().norm()));
  }
}

TEST(Deskew, ConstantTwistMovesPointsIntoTheEndFrame) {
  // A sensor turning at 3 rad/s while moving at 20 m/s observes fixed world points over 0.1 s;
  // each measurement in the sensor frame of its own instant maps back onto the world point.
  Vec6d twist;
  twist << 20.0, 0.5, 0.0, 0.1, -0.2, 3.0;
  const double duration = 0.1;
  const SE3 T_end = SE3::exp((Vec6d() << 5, 1, 0, 0, 0, 0.4).finished());
  const ScanMotion m = ScanMotion::constant_twist(twist.cast<float>(), static_cast<float>(duration));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-30.0, 30.0), ut(0.0, duration);
  double worst = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d world(u(rng), u(rng), 0.1 * u(rng));
    const double tau = ut(rng);
    const SE3 T_tau = T_end * SE3::exp((tau - duration) * twist);  // right-perturbation motion
    const Eigen::Vector3d measured = T_tau.inverse() * world;
    const Eigen::Vector3f corrected = deskew_point(m, measured.cast<float>(), static_cast<float>(tau));
    const Eigen::Vector3d expected = T_end.inverse() * world;
    worst = std::max(worst, (corrected.cast<double>() - expected).norm());
  }
  EXPECT_LT(worst, 1e-4);  // float precision over tens of metres
  // without correction the same points are off by up to metres
  const Eigen::Vector3d w(20.0, 0.0, 0.0);
  const Eigen::Vector3d at_start = (T_end * SE3::exp(-duration * twist)).inverse() * w;
  EXPECT_GT((at_start - T_end.inverse() * w).norm(), 1.0);
}

#include "farlio/deskew/motion_fit.hpp"

TEST(Deskew, RegressionRecoversAConstantTwist) {
  // Poses of a sensor moving with a constant body twist, sampled over a scan: the linear fit
  // of log(T_end^-1 T(tau)) gives offset = -D w and rate = w.
  Vec6d twist;
  twist << 30.0, -1.0, 0.2, 0.05, 0.1, 1.5;
  const double duration = 0.1;
  const SE3 T_end = SE3::exp((Vec6d() << 10, 2, 1, 0.1, 0, 0.3).finished());
  std::vector<std::pair<double, SE3>> samples;
  for (int i = 0; i <= 10; ++i) {
    const double tau = duration * i / 10.0;
    samples.emplace_back(tau, T_end * SE3::exp((tau - duration) * twist));
  }
  const ScanMotion m = fit_scan_motion(samples, T_end);
  const ScanMotion expected = ScanMotion::constant_twist(twist.cast<float>(), static_cast<float>(duration));
  EXPECT_LT((m.rate - expected.rate).norm(), 1e-3f);
  EXPECT_LT((m.offset - expected.offset).norm(), 1e-4f);
  EXPECT_TRUE(fit_scan_motion({samples.front()}, T_end).is_identity());  // one sample: no fit
}

TEST(Deskew, TheInterpolatedTableStaysWithinItsBoundOfTheExactCorrection) {
  // The worst motions of the profiles and beyond: 3 rad/s (handheld shaking) with 70 m/s
  // (250 km/h) over a 0.1 s scan, a motion-fit offset not parallel to the rate, points at 50 m.
  // The bound of DeskewTable: (3.2 * 0.1 / 64)^2 / 8 rad = 3.1e-6 rad, 0.16 mm at 50 m, and about
  // as much from the translation's curvature at 70 m/s.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), tau(0.0f, 0.1f);
  constexpr float kDuration = 0.1f, kRange = 50.0f, kBound = 0.3e-3f;
  const Vec6f rate = (Vec6f() << 70.0f, 2.0f, -1.0f, 0.5f, -1.0f, 3.0f).finished();
  const Vec6f offset = -kDuration * rate + (Vec6f() << 0.3f, -0.2f, 0.1f, 0.02f, -0.03f, 0.01f).finished();
  const ScanMotion motion{offset, rate};
  const DeskewTable table = DeskewTable::sample(motion, kDuration);
  float worst = 0.0f;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3f p = Eigen::Vector3f(u(rng), u(rng), 0.2f * u(rng)).normalized() * kRange;
    const float t = i == 0 ? 0.0f : (i == 1 ? kDuration : tau(rng));
    worst = std::max(worst, (deskew_point(table, p, t) - deskew_point(motion, p, t)).norm());
  }
  EXPECT_LT(worst, kBound);
  EXPECT_GT(worst, 1e-6f);  // it does interpolate: the check compares two different computations
  // at the sample times the table is exact (float rounding)
  for (int k = 0; k <= DeskewTable::kSegments; ++k) {
    const float t = kDuration * static_cast<float>(k) / DeskewTable::kSegments;
    const Eigen::Vector3f p(kRange, 0.0f, 1.0f);
    EXPECT_LT((deskew_point(table, p, t) - deskew_point(motion, p, t)).norm(), 2e-5f) << "sample " << k;
  }
  // a zero-duration scan: every point takes the pose at 0
  const DeskewTable instant = DeskewTable::sample(motion, 0.0f);
  const Eigen::Vector3f p(10.0f, 2.0f, 0.5f);
  EXPECT_LT((deskew_point(instant, p, 0.05f) - deskew_point(motion, p, 0.0f)).norm(), 1e-5f);
}
