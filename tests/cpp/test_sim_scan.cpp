// LiDAR scans: exact motion distortion and its compensation, sizes, per-point times, determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;
using namespace farlio::sim;

namespace {
constexpr double kSurfaceTolerance_m = 2e-3;  // float32 point coordinates at up to ~200 m
constexpr std::size_t kPointStride = 53;      // check every 53rd point

/// A scan index at which the body moves (every profile starts standing still).
std::size_t moving_scan(Profile p) {
  switch (p) {
    case Profile::Racetrack: return 200;  // 10 s: near top speed at the end of the standing start
    case Profile::Urban: return 100;
    case Profile::Handheld: return 40;
    case Profile::Tunnel: return 100;  // 10 s: ~16 m/s, approaching the tunnel portal
    case Profile::Garage: return 100;  // 10 s: on the bottom aisle
  }
  return 0;
}

SimConfig short_config(Profile p, bool noise_free) {
  SimConfig c = default_config(p);
  c.duration_s = 12.0;
  c.noise_free = noise_free;
  return c;
}

/// Range along the ray from the sensor at the point's firing time to the point, minus the
/// range the scene returns along that ray. Zero for an exact, noise-free point.
double surface_residual_m(const SequenceGenerator& gen, const Scan& scan, std::size_t k, const SE3& T_world_lidar) {
  const LidarSensor& l = gen.lidars()[scan.sensor_id[k]];
  const SE3 T_world_sensor = T_world_lidar * l.T_lidar_sensor;
  const Eigen::Vector3d q = T_world_lidar * scan.points[k].cast<double>();
  const Eigen::Vector3d origin = T_world_sensor.translation();
  const double range = (q - origin).norm();
  const auto hit = gen.scene().cast(origin, (q - origin) / range, l.max_range_m);
  return hit ? std::abs(hit->range_m - range) : std::numeric_limits<double>::infinity();
}

SE3 lidar_pose_at(const SequenceGenerator& gen, const Scan& scan, double time_s) {
  const auto stamp = scan.start_stamp_ns + std::llround(time_s * 1e9);
  return gen.state(stamp).pose_world_body * gen.T_imu_lidar();
}
}  // namespace

class SimScanProfile : public ::testing::TestWithParam<Profile> {};

TEST_P(SimScanProfile, DeDistortedPointsLieOnTheScene) {
  const SequenceGenerator gen(short_config(GetParam(), true));
  const Scan scan = gen.scan(moving_scan(GetParam()));
  ASSERT_GT(scan.size(), 1000U);
  ASSERT_GT(gen.state(scan.start_stamp_ns).velocity_world_m_s.norm(), 0.5);
  std::size_t checked = 0, off_with_end_pose = 0;
  const SE3 end_pose = lidar_pose_at(gen, scan, scan.duration_s());
  for (std::size_t k = 0; k < scan.size(); k += kPointStride) {
    EXPECT_LT(surface_residual_m(gen, scan, k, lidar_pose_at(gen, scan, scan.time_s[k])), kSurfaceTolerance_m) << k;
    // Without de-distortion (every point at the end pose) early points miss the surface.
    if (surface_residual_m(gen, scan, k, end_pose) > 10 * kSurfaceTolerance_m) ++off_with_end_pose;
    ++checked;
  }
  EXPECT_GT(checked, 100U);
  // Surfaces parallel to the motion hide the error, so only a share of points shows it.
  EXPECT_GT(off_with_end_pose, checked / 100) << "motion distortion should matter at these speeds";
}

TEST_P(SimScanProfile, MotionCompensatedPointsAreTheSameWorldPointsSeenFromTheScanEnd) {
  const SequenceGenerator gen(short_config(GetParam(), false));
  const Scan scan = gen.scan(moving_scan(GetParam()));
  const Scan compensated = gen.motion_compensated(scan);
  EXPECT_FALSE(compensated.has_time());
  EXPECT_EQ(compensated.start_stamp_ns, scan.end_stamp_ns);
  EXPECT_EQ(compensated.end_stamp_ns, scan.end_stamp_ns);
  ASSERT_EQ(compensated.size(), scan.size());
  EXPECT_EQ(compensated.intensity, scan.intensity);
  const SE3 end_pose = lidar_pose_at(gen, scan, scan.duration_s());
  std::size_t moved = 0;
  for (std::size_t k = 0; k < scan.size(); k += kPointStride) {
    const Eigen::Vector3d world = lidar_pose_at(gen, scan, scan.time_s[k]) * scan.points[k].cast<double>();
    EXPECT_LT((end_pose * compensated.points[k].cast<double>() - world).norm(), kSurfaceTolerance_m) << k;
    if ((compensated.points[k] - scan.points[k]).norm() > 10 * kSurfaceTolerance_m) ++moved;
  }
  EXPECT_GT(moved, 0U) << "the body moves during this scan";
}

TEST_P(SimScanProfile, TimesAndStampsAreConsistent) {
  const SequenceGenerator gen(short_config(GetParam(), false));
  const Scan scan = gen.scan(3);
  scan.validate("sim scan");
  EXPECT_EQ(scan.start_stamp_ns, gen.config().start_stamp_ns + 3 * gen.scan_period_ns());
  EXPECT_EQ(scan.end_stamp_ns - scan.start_stamp_ns, std::llround(1e9 / gen.lidar_rate_hz()));
  ASSERT_EQ(scan.time_s.size(), scan.size());
  ASSERT_EQ(scan.sensor_id.size(), scan.size());
  const auto period = static_cast<float>(scan.duration_s());
  for (std::size_t k = 0; k < scan.size(); ++k) {
    ASSERT_GE(scan.time_s[k], 0.0F);
    ASSERT_LT(scan.time_s[k], period);
    if (k > 0) {
      ASSERT_GE(scan.time_s[k], scan.time_s[k - 1]) << "points are in firing order";
    }
    ASSERT_LT(scan.sensor_id[k], gen.lidars().size());
    const double r = scan.points[k].norm();
    ASSERT_TRUE(std::isfinite(r));
  }
  // The scan spans (almost) its whole period.
  EXPECT_GT(scan.time_s.back() - scan.time_s.front(), 0.95F * period);
}

TEST_P(SimScanProfile, SameSeedBitIdenticalInAnyOrderOtherSeedDiffers) {
  const SimConfig cfg = short_config(GetParam(), false);
  const SequenceGenerator a(cfg), b(cfg);
  const Scan a5 = a.scan(5);
  (void)b.scan(9);
  const Scan b5 = b.scan(5);
  ASSERT_EQ(a5.size(), b5.size());
  EXPECT_EQ(a5.points, b5.points);
  EXPECT_EQ(a5.time_s, b5.time_s);
  EXPECT_EQ(a5.intensity, b5.intensity);
  EXPECT_EQ(a5.sensor_id, b5.sensor_id);
  SimConfig other = cfg;
  other.seed = cfg.seed + 1;
  const Scan c5 = SequenceGenerator(other).scan(5);
  EXPECT_NE(a5.points, c5.points);
}

INSTANTIATE_TEST_SUITE_P(Profiles, SimScanProfile,
                         ::testing::Values(Profile::Racetrack, Profile::Urban, Profile::Handheld, Profile::Tunnel,
                                           Profile::Garage),
                         [](const ::testing::TestParamInfo<Profile>& param_info) {
                           return profile_name(param_info.param);
                         });

TEST(SimScan, SizesNearTargets) {
  // Racetrack ~200k points (3 x 128 x 570 rays), urban ~120k (64 x 1875 rays).
  const Scan race = SequenceGenerator(short_config(Profile::Racetrack, false)).scan(1);
  EXPECT_GT(race.size(), 170'000U);
  EXPECT_LT(race.size(), 220'000U);
  std::array<std::size_t, 3> per_sensor{};
  for (const auto id : race.sensor_id) ++per_sensor.at(id);
  for (const auto n : per_sensor) EXPECT_GT(n, race.size() / 5) << "every sensor contributes";
  const Scan urban = SequenceGenerator(short_config(Profile::Urban, false)).scan(1);
  EXPECT_GT(urban.size(), 100'000U);
  EXPECT_LE(urban.size(), 120'000U);
  const Scan hand = SequenceGenerator(short_config(Profile::Handheld, false)).scan(1);
  EXPECT_GT(hand.size(), 50'000U);
  EXPECT_LE(hand.size(), 57'600U);
}

TEST(SimScan, RangeNoiseHasConfiguredSpread) {
  SimConfig cfg = short_config(Profile::Urban, false);
  cfg.noise.dropout_probability = 0.0;
  const SequenceGenerator gen(cfg);
  const Scan scan = gen.scan(2);
  double sum_sq = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < scan.size(); k += kPointStride) {
    const SE3 T = lidar_pose_at(gen, scan, scan.time_s[k]);
    const Eigen::Vector3d q = T * scan.points[k].cast<double>();
    const Eigen::Vector3d o = T.translation();
    const auto hit = gen.scene().cast(o, (q - o).normalized(), 1e3);
    ASSERT_TRUE(hit);
    const double e = (q - o).norm() - hit->range_m;
    if (std::abs(e) > 10 * cfg.noise.range_noise_std_m) continue;  // a noisy point near an edge
    sum_sq += e * e;
    ++n;
  }
  EXPECT_NEAR(std::sqrt(sum_sq / static_cast<double>(n)), cfg.noise.range_noise_std_m,
              0.15 * cfg.noise.range_noise_std_m);
}
