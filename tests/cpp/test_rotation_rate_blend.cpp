// The rotation rate that undistorts a scan, blended from the gyro's and the LiDAR's constant twist
// by their errors (deskew/rotation_rate_blend.hpp): on simulated rates with a known answer, the
// blend's error against the truth is near the least any fixed blend can reach, whichever source is
// the better one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "farlio/deskew/rotation_rate_blend.hpp"

using namespace farlio::deskew;

namespace {

constexpr std::int64_t kScanNs = 50'000'000;  // 20 Hz
constexpr int kScans = 2000;

struct BlendRun {
  double blended_rms = 0.0;  ///< of the blended rate against the truth (rad/s), per axis mean
  double gyro_rms = 0.0;
  double twist_rms = 0.0;
  double mean_weight = 0.0;  ///< of the gyro, over the scans after the first 10 s
};

/// Scans whose true rate changes by N(0, change_std) from one interval to the next; the gyro
/// measures it with N(0, gyro_std), the constant twist is the previous interval's true rate.
BlendRun run_blend(double gyro_std, double change_std, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  RotationRateBlend blend;
  const Eigen::Vector3d gyro_variance = Eigen::Vector3d::Constant(gyro_std * gyro_std);
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();
  double blended = 0.0, gyro = 0.0, twist = 0.0, weight = 0.0;
  int counted = 0;
  for (int k = 0; k < kScans; ++k) {
    const Eigen::Vector3d previous = truth;
    for (int i = 0; i < 3; ++i) truth[i] += change_std * unit(rng);
    Eigen::Vector3d measured = truth;
    for (int i = 0; i < 3; ++i) measured[i] += gyro_std * unit(rng);
    const Eigen::Vector3d rate = blend.blend(measured, previous, gyro_variance, k * kScanNs);
    if (k < 200) continue;  // the running mean settles over its memory
    blended += (rate - truth).squaredNorm();
    gyro += (measured - truth).squaredNorm();
    twist += (previous - truth).squaredNorm();
    weight += blend.gyro_weight().mean();
    ++counted;
  }
  const double n = 3.0 * counted;
  return {std::sqrt(blended / n), std::sqrt(gyro / n), std::sqrt(twist / n), weight / counted};
}

double optimum(double gyro_std, double change_std) {
  const double g = gyro_std * gyro_std, t = change_std * change_std;
  return std::sqrt(g * t / (g + t));
}

}  // namespace

TEST(RotationRateBlend, ANoisyGyroOnASmoothMotionTakesTheTwist) {
  // a vibrating race car's gyro over a 50 ms scan (0.013 rad/s) on a car whose yaw rate changes by
  // 0.002 rad/s from one scan to the next
  for (unsigned seed : {1u, 2u, 3u}) {
    const BlendRun r = run_blend(0.013, 0.002, seed);
    EXPECT_LT(r.mean_weight, 0.2) << "seed " << seed;
    EXPECT_LT(r.blended_rms, 0.3 * r.gyro_rms) << "seed " << seed;
    EXPECT_LT(r.blended_rms, 1.2 * optimum(0.013, 0.002)) << "seed " << seed;
  }
}

TEST(RotationRateBlend, AQuietGyroOnAQuickMotionIsUsedAsMeasured) {
  // a tactical gyro (0.001 rad/s over a scan) on a walker looking around (0.5 rad/s a scan)
  for (unsigned seed : {1u, 2u, 3u}) {
    const BlendRun r = run_blend(0.001, 0.5, seed);
    EXPECT_GT(r.mean_weight, 0.99) << "seed " << seed;
    EXPECT_LT(r.blended_rms, 1.02 * r.gyro_rms) << "seed " << seed;
    EXPECT_LT(r.blended_rms, 0.01 * r.twist_rms) << "seed " << seed;
  }
}

TEST(RotationRateBlend, EqualErrorsAreWeighedEqually) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const BlendRun r = run_blend(0.01, 0.01, seed);
    EXPECT_NEAR(r.mean_weight, 0.5, 0.1) << "seed " << seed;
    EXPECT_LT(r.blended_rms, 1.1 * optimum(0.01, 0.01)) << "seed " << seed;
    EXPECT_LT(r.blended_rms, 0.85 * std::min(r.gyro_rms, r.twist_rms)) << "seed " << seed;
  }
}

TEST(RotationRateBlend, ATurnThatBeginsTakesTheGyrosRate) {
  // a smooth run with a noisy gyro weighs the twist; then the yaw rate steps by 0.5 rad/s, which
  // the twist of the interval before cannot know: that scan takes the gyro's rate
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.013);
  RotationRateBlend blend;
  const Eigen::Vector3d gyro_variance = Eigen::Vector3d::Constant(0.013 * 0.013);
  for (int k = 0; k < 400; ++k) {
    blend.blend(Eigen::Vector3d(noise(rng), noise(rng), noise(rng)), Eigen::Vector3d::Zero(), gyro_variance,
                k * kScanNs);
  }
  ASSERT_LT(blend.gyro_weight().z(), 0.2);
  const Eigen::Vector3d turning(noise(rng), noise(rng), 0.5 + noise(rng));
  const Eigen::Vector3d rate = blend.blend(turning, Eigen::Vector3d::Zero(), gyro_variance, 400 * kScanNs);
  EXPECT_EQ(blend.gyro_weight().z(), 1.0);
  EXPECT_EQ(rate.z(), turning.z());
  EXPECT_LT(blend.gyro_weight().x(), 1.0);  // the other axes did not change
}

TEST(RotationRateBlend, WhileTheGyrosNoiseIsUnknownTheGyroIsUsed) {
  RotationRateBlend blend;
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d gyro(0.1, -0.2, 0.3 + 0.01 * k), twist(0.0, 0.0, 0.3);
    EXPECT_EQ(blend.blend(gyro, twist, std::nullopt, k * kScanNs), gyro);
    EXPECT_EQ(blend.gyro_weight(), Eigen::Vector3d::Ones());
  }
}
