// The IMU readings must be consistent with the poses: integrating the noise-free IMU from the
// true state for 1 s must land on the true pose.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;
using namespace farlio::sim;

namespace {
constexpr double kHorizon_s = 1.0;
constexpr int kSubsteps = 8;
constexpr double kMaxPositionError_m = 0.05;
constexpr double kMaxRotationError_deg = 0.1;

struct Integrated {
  Mat3d R;
  Eigen::Vector3d v, p;
};

/// Strapdown integration over [k0, k0 + n] with linear interpolation between samples and
/// midpoint sub-steps.
Integrated integrate(const std::vector<ImuSample>& imu, std::size_t k0, std::size_t n, const BodyState& start,
                     double gravity_m_s2) {
  const Eigen::Vector3d g(0.0, 0.0, -gravity_m_s2);
  Integrated x{start.pose_world_body.rotation(), start.velocity_world_m_s, start.pose_world_body.translation()};
  for (std::size_t k = k0; k < k0 + n; ++k) {
    const double dt = static_cast<double>(imu[k + 1].stamp_ns - imu[k].stamp_ns) * 1e-9;
    const double h = dt / kSubsteps;
    for (int j = 0; j < kSubsteps; ++j) {
      const double u = (j + 0.5) / kSubsteps;
      const Eigen::Vector3d w = (1 - u) * imu[k].gyro_rad_s + u * imu[k + 1].gyro_rad_s;
      const Eigen::Vector3d f = (1 - u) * imu[k].accel_m_s2 + u * imu[k + 1].accel_m_s2;
      const Mat3d R_mid = x.R * so3_exp(0.5 * h * w);
      const Eigen::Vector3d a = R_mid * f + g;
      x.p += x.v * h + 0.5 * a * h * h;
      x.v += a * h;
      x.R = x.R * so3_exp(h * w);
    }
  }
  return x;
}

/// Times worth testing: the start, the first movement, the sharpest turn and the hardest
/// acceleration.
std::vector<double> interesting_times(const SequenceGenerator& gen, double horizon_end_s) {
  double t_turn = 0.0, best_rate = -1.0, t_accel = 0.0, best_accel = -1.0, t_move = -1.0;
  for (double t = 0.0; t < horizon_end_s; t += 0.05) {
    const BodyState s = gen.state(gen.config().start_stamp_ns + std::llround(t * 1e9));
    if (t_move < 0.0 && s.velocity_world_m_s.norm() > 1e-3) t_move = std::max(0.0, t - 0.05);
    if (s.angular_velocity_body_rad_s.norm() > best_rate) {
      best_rate = s.angular_velocity_body_rad_s.norm();
      t_turn = t;
    }
    if (s.acceleration_world_m_s2.norm() > best_accel) {
      best_accel = s.acceleration_world_m_s2.norm();
      t_accel = t;
    }
  }
  return {0.0, std::max(0.0, t_move), std::max(0.0, t_turn - 0.5), std::max(0.0, t_accel - 0.5), 0.37 * horizon_end_s};
}

/// extra_times_s: more start times to check, on top of interesting_times().
void check_profile(Profile profile, double search_s, const std::vector<double>& extra_times_s = {}) {
  SimConfig cfg = default_config(profile);
  cfg.noise_free = true;
  cfg.duration_s = search_s + 2.0 * kHorizon_s;
  const SequenceGenerator gen(cfg);
  const std::vector<ImuSample> imu = gen.imu();
  const auto n = static_cast<std::size_t>(std::llround(kHorizon_s * gen.imu_rate_hz()));
  std::vector<double> times = interesting_times(gen, search_s);
  times.insert(times.end(), extra_times_s.begin(), extra_times_s.end());
  for (const double t0 : times) {
    const auto k0 = static_cast<std::size_t>(std::llround(t0 * gen.imu_rate_hz()));
    ASSERT_LT(k0 + n, imu.size());
    const BodyState start = gen.state(imu[k0].stamp_ns);
    const BodyState end = gen.state(imu[k0 + n].stamp_ns);
    const Integrated x = integrate(imu, k0, n, start, gen.gravity_m_s2());
    const double pos_err = (x.p - end.pose_world_body.translation()).norm();
    const double rot_err_deg =
        so3_log(x.R.transpose() * end.pose_world_body.rotation()).norm() * 180.0 / std::numbers::pi;
    // The motion over the horizon is far larger than the tolerance, so a wrong reading fails.
    const double travelled = (end.pose_world_body.translation() - start.pose_world_body.translation()).norm();
    EXPECT_LT(pos_err, kMaxPositionError_m) << profile_name(profile) << " t0=" << t0 << " travelled " << travelled;
    EXPECT_LT(rot_err_deg, kMaxRotationError_deg) << profile_name(profile) << " t0=" << t0;
  }
}
}  // namespace

TEST(SimImu, RacetrackNoiseFreeIntegratesToTruth) {
  // The standing start: at rest for 2 s, then accelerating down the start straight for ~9 s.
  // Horizons starting at 1.5 s (rest into launch) and 2.5, 5 and 8 s (hard acceleration).
  const std::vector<double> launch_s = {2.5, 5.0, 8.0};
  const SequenceGenerator gen(default_config(Profile::Racetrack));
  for (const double t : launch_s) {  // these horizons lie inside the acceleration phase
    const BodyState s = gen.state(gen.config().start_stamp_ns + std::llround((t + 0.5 * kHorizon_s) * 1e9));
    const double v = s.velocity_world_m_s.norm();
    ASSERT_GT(v, 0.1) << t;
    EXPECT_GT(s.acceleration_world_m_s2.dot(s.velocity_world_m_s) / v, 1.0) << "accelerating mid-horizon at " << t;
  }
  std::vector<double> times = launch_s;
  times.push_back(1.5);  // from rest into the launch
  check_profile(Profile::Racetrack, 40.0, times);
}

TEST(SimImu, UrbanNoiseFreeIntegratesToTruth) { check_profile(Profile::Urban, 60.0); }
TEST(SimImu, HandheldNoiseFreeIntegratesToTruth) { check_profile(Profile::Handheld, 40.0); }
TEST(SimImu, TunnelNoiseFreeIntegratesToTruth) { check_profile(Profile::Tunnel, 40.0); }

TEST(SimImu, AtRestReadsGravityUp) {
  for (const Profile p : {Profile::Urban, Profile::Racetrack, Profile::Tunnel}) {  // all start standing still
    SimConfig cfg = default_config(p);
    cfg.noise_free = true;
    cfg.duration_s = 1.0;
    const SequenceGenerator gen(cfg);
    for (const ImuSample& s : {gen.imu().front(), gen.imu().back()}) {
      const Mat3d R = gen.state(s.stamp_ns).pose_world_body.rotation();
      EXPECT_NEAR((R * s.accel_m_s2).z(), gen.gravity_m_s2(), 1e-9) << profile_name(p);
      EXPECT_NEAR((R * s.accel_m_s2).head<2>().norm(), 0.0, 1e-9) << profile_name(p);
      EXPECT_LT(s.gyro_rad_s.norm(), 1e-12) << profile_name(p);
    }
  }
}

// imu_time_offset_s: the samples fall that long after the whole IMU periods (an IMU not phase-locked
// to the LiDAR), each the reading of the motion at its own stamp; an offset of a period or more is
// an error naming the field.
TEST(SimImu, AnOffsetMovesTheSamplesBetweenThePeriods) {
  SimConfig cfg = default_config(Profile::Urban);
  cfg.noise_free = true;
  cfg.duration_s = 2.0;
  cfg.motion_start_s = 25.0;  // turning
  cfg.imu_rate_hz = 10.0;
  cfg.imu_time_offset_s = 0.04;
  const SequenceGenerator gen(cfg);
  const std::vector<ImuSample> imu = gen.imu();
  ASSERT_EQ(imu.size(), 20u);  // 0.04, 0.14, ..., 1.94 s
  for (std::size_t k = 0; k < imu.size(); ++k) {
    EXPECT_EQ(imu[k].stamp_ns, cfg.start_stamp_ns + static_cast<std::int64_t>(k) * 100'000'000 + 40'000'000);
    EXPECT_LT((imu[k].gyro_rad_s - gen.state(imu[k].stamp_ns).angular_velocity_body_rad_s).norm(), 1e-12);
  }
  cfg.imu_time_offset_s = 0.1;
  EXPECT_THROW(SequenceGenerator{cfg}, std::invalid_argument);
}

TEST(SimImu, NoiseMatchesConfiguredStatistics) {
  SimConfig noisy = default_config(Profile::Racetrack);
  noisy.duration_s = 5.0;
  SimConfig clean = noisy;
  clean.noise_free = true;
  clean.noise.gyro_bias_initial_rad_s.setZero();
  noisy.noise.gyro_bias_walk_rad_s2_sqrt_hz = 0.0;
  noisy.noise.gyro_bias_initial_rad_s.setZero();
  const auto a = SequenceGenerator(noisy).imu(), b = SequenceGenerator(clean).imu();
  ASSERT_EQ(a.size(), b.size());
  double sum = 0.0, sum_sq = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double e = a[k].gyro_rad_s.x() - b[k].gyro_rad_s.x();
    sum += e;
    sum_sq += e * e;
  }
  const double n = static_cast<double>(a.size());
  const double std_dev = std::sqrt(sum_sq / n - (sum / n) * (sum / n));
  EXPECT_NEAR(std_dev, noisy.noise.gyro_noise_std_rad_s, 0.05 * noisy.noise.gyro_noise_std_rad_s);
  EXPECT_NEAR(sum / n, 0.0, 4.0 * noisy.noise.gyro_noise_std_rad_s / std::sqrt(n));
}

TEST(SimImu, SameSeedIsBitIdenticalOtherSeedDiffers) {
  SimConfig cfg = default_config(Profile::Handheld);
  cfg.duration_s = 3.0;
  const auto a = SequenceGenerator(cfg).imu(), b = SequenceGenerator(cfg).imu();
  cfg.seed = 2;
  const auto c = SequenceGenerator(cfg).imu();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  bool any_diff = false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].stamp_ns, b[k].stamp_ns);
    EXPECT_TRUE(a[k].gyro_rad_s == b[k].gyro_rad_s && a[k].accel_m_s2 == b[k].accel_m_s2) << k;
    any_diff |= a[k].accel_m_s2 != c[k].accel_m_s2;
    if (k > 0) {
      EXPECT_GT(a[k].stamp_ns, a[k - 1].stamp_ns);
    }
  }
  EXPECT_TRUE(any_diff);
}
