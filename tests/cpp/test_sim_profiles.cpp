// The profiles' trajectories stay within their stated ranges, and the configuration API.
#include <gtest/gtest.h>

#include <cmath>

#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;
using namespace farlio::sim;

namespace {
constexpr double kSampleRate_hz = 50.0;
constexpr double kEps = 1e-6;

struct Extremes {
  double max_speed_m_s = 0.0, min_speed_m_s = 1e9, max_lateral_m_s2 = 0.0, max_rate_rad_s = 0.0;
  double z_min_m = 1e9, z_max_m = -1e9, standstill_s = 0.0;
};

Extremes sample(const SequenceGenerator& gen, double duration_s, double from_s = 0.0) {
  Extremes e;
  for (double t = from_s; t <= duration_s; t += 1.0 / kSampleRate_hz) {
    const BodyState s = gen.state(gen.config().start_stamp_ns + std::llround(t * 1e9));
    const double v = s.velocity_world_m_s.norm();
    e.max_speed_m_s = std::max(e.max_speed_m_s, v);
    e.min_speed_m_s = std::min(e.min_speed_m_s, v);
    if (v > kEps)
      e.max_lateral_m_s2 =
          std::max(e.max_lateral_m_s2, s.acceleration_world_m_s2.cross(s.velocity_world_m_s).norm() / v);
    if (v < kEps) e.standstill_s += 1.0 / kSampleRate_hz;
    e.max_rate_rad_s = std::max(e.max_rate_rad_s, s.angular_velocity_body_rad_s.norm());
    e.z_min_m = std::min(e.z_min_m, s.pose_world_body.translation().z());
    e.z_max_m = std::max(e.z_max_m, s.pose_world_body.translation().z());
  }
  return e;
}
}  // namespace

TEST(SimProfiles, RacetrackSpeedAndCornering) {
  // Over the default duration (standing start, then one full lap): top speed and cornering.
  const SimConfig cfg = default_config(Profile::Racetrack);
  const SequenceGenerator gen(cfg);
  const Extremes e = sample(gen, cfg.duration_s);
  EXPECT_GE(e.max_speed_m_s, 60.0);
  EXPECT_LE(e.max_speed_m_s, 70.0 + 1e-3);
  EXPECT_GE(e.max_lateral_m_s2, 15.0);
  EXPECT_LE(e.max_lateral_m_s2, 27.0);
  const double lap_m = std::stod(gen.description().at("lap_length_m"));
  EXPECT_GT(lap_m, 3000.0);
  const double first_lap_s = std::stod(gen.description().at("first_lap_time_s"));
  EXPECT_LE(first_lap_s, cfg.duration_s) << "the default duration covers the whole first lap";
  // Once under way, a race car never slows down much (later laps too).
  const Extremes racing = sample(gen, 2.0 * first_lap_s, 12.0);
  EXPECT_GT(racing.min_speed_m_s, 20.0) << "a race car never stops";
  EXPECT_LE(racing.max_speed_m_s, 70.0 + 1e-3);
  EXPECT_LE(racing.max_lateral_m_s2, 27.0);
}

TEST(SimProfiles, RacetrackStandingStart) {
  const SequenceGenerator gen(default_config(Profile::Racetrack));
  const auto state_at = [&](double t) { return gen.state(gen.config().start_stamp_ns + std::llround(t * 1e9)); };
  // At rest on the grid for 2 s: an odometry can start with a zero velocity.
  const Extremes rest = sample(gen, 2.0);
  EXPECT_LT(rest.max_speed_m_s, 1e-6);
  EXPECT_LT(rest.max_rate_rad_s, 1e-9);
  // Then it accelerates down the start straight: speed grows monotonically to near top speed,
  // with a longitudinal acceleration within the limit.
  double prev_v = 0.0, max_long = 0.0;
  for (double t = 2.05; t <= 10.0; t += 0.05) {
    const BodyState s = state_at(t);
    const double v = s.velocity_world_m_s.norm();
    EXPECT_GT(v, prev_v) << t;
    prev_v = v;
    max_long = std::max(max_long, s.acceleration_world_m_s2.dot(s.velocity_world_m_s) / v);
    EXPECT_LT(s.angular_velocity_body_rad_s.norm(), 1e-9) << "still on the straight at " << t;
  }
  EXPECT_GT(prev_v, 60.0);
  EXPECT_GT(max_long, 10.0);
  EXPECT_LE(max_long, 15.0 + 1e-6);
  // The circuit is closed: the first lap ends where the car started, and so does every later
  // (steady) lap.
  const double first_lap_s = std::stod(gen.description().at("first_lap_time_s"));
  const double lap_s = std::stod(gen.description().at("lap_time_s"));
  EXPECT_GT(first_lap_s, lap_s + 2.0) << "rest and acceleration cost time";
  const Eigen::Vector3d p0 = state_at(0.0).pose_world_body.translation();
  EXPECT_LT((p0 - state_at(first_lap_s).pose_world_body.translation()).norm(), 1e-3);
  const auto p1 = state_at(first_lap_s + 1.0).pose_world_body;
  const auto p2 = state_at(first_lap_s + 1.0 + lap_s).pose_world_body;
  EXPECT_LT((p1.translation() - p2.translation()).norm(), 1e-3);
  // Crossing from the first lap into the steady laps is smooth (same speed and acceleration).
  const BodyState a = state_at(first_lap_s - 1e-4), b = state_at(first_lap_s + 1e-4);
  EXPECT_LT((a.velocity_world_m_s - b.velocity_world_m_s).norm(), 1e-3);
  EXPECT_LT((a.acceleration_world_m_s2 - b.acceleration_world_m_s2).norm(), 1e-3);
  EXPECT_NEAR(a.velocity_world_m_s.norm(), 70.0, 1e-6);
}

TEST(SimProfiles, UrbanHasStopsTurnsAndSlopes) {
  const SimConfig cfg = default_config(Profile::Urban);
  const SequenceGenerator gen(cfg);
  const Extremes e = sample(gen, cfg.duration_s);
  EXPECT_GE(e.max_speed_m_s, 12.0);
  EXPECT_LE(e.max_speed_m_s, 15.0 + 1e-3);
  EXPECT_GT(e.standstill_s, 5.0) << "full stops";
  EXPECT_GT(e.z_max_m - e.z_min_m, 3.0) << "the road goes up and down";
  EXPECT_GT(e.max_rate_rad_s, 0.3) << "turns";
  EXPECT_LE(e.max_lateral_m_s2, 4.5 + 0.1);
}

TEST(SimProfiles, HandheldWalksAndTurnsQuickly) {
  const SimConfig cfg = default_config(Profile::Handheld);
  const SequenceGenerator gen(cfg);
  const Extremes e = sample(gen, cfg.duration_s);
  EXPECT_GE(e.max_rate_rad_s, 2.0);
  EXPECT_LE(e.max_rate_rad_s, 3.0 + 1e-3);
  EXPECT_GE(e.max_speed_m_s, 1.2);
  EXPECT_LE(e.max_speed_m_s, 2.0);
  EXPECT_GT(e.z_max_m - e.z_min_m, 0.02) << "walking bob";
  EXPECT_LT(e.z_max_m - e.z_min_m, 0.1);
}

TEST(SimProfiles, TunnelDrivesStraightThroughTheTunnel) {
  const SimConfig cfg = default_config(Profile::Tunnel);
  const SequenceGenerator gen(cfg);
  const auto fact = [&](const char* key) { return std::stod(gen.description().at(key)); };
  const auto state_at = [&](double t) { return gen.state(cfg.start_stamp_ns + std::llround(t * 1e9)); };
  const Extremes e = sample(gen, cfg.duration_s);
  // 0 -> 100 km/h after 2 s at rest, straight and level: no rotation, no height change.
  EXPECT_GT(e.max_speed_m_s, 27.7);
  EXPECT_LE(e.max_speed_m_s, 100.0 / 3.6 + 1e-6);
  EXPECT_NEAR(e.standstill_s, 2.0, 0.05);
  EXPECT_LT(e.max_rate_rad_s, 1e-9);
  EXPECT_LT(e.z_max_m - e.z_min_m, 1e-9);
  EXPECT_LT(e.max_lateral_m_s2, 1e-9);
  for (double t = 0.0; t <= cfg.duration_s; t += 1.0) {
    const Eigen::Vector3d p = state_at(t).pose_world_body.translation();
    EXPECT_LT(std::abs(p.y()), 1e-9) << "on the tunnel's centre line at " << t;
  }
  // The featureless section: several hundred metres inside the tunnel, driven at cruise speed,
  // and its bounds in time and x agree with the motion.
  const double x0 = fact("featureless_start_x_m"), x1 = fact("featureless_end_x_m");
  const double t0 = fact("featureless_start_s"), t1 = fact("featureless_end_s");
  EXPECT_GT(x0, fact("tunnel_start_x_m"));
  EXPECT_LT(x1, fact("tunnel_end_x_m"));
  EXPECT_GE(x1 - x0, 500.0);
  EXPECT_GT(t0, 0.0);
  EXPECT_LT(t1, cfg.duration_s);
  EXPECT_NEAR(state_at(t0).pose_world_body.translation().x(), x0, 1e-3);
  EXPECT_NEAR(state_at(t1).pose_world_body.translation().x(), x1, 1e-3);
  EXPECT_GT(state_at(t0).velocity_world_m_s.norm(), 25.0);
  // The default duration ends outside, after the exit portal.
  EXPECT_GT(state_at(cfg.duration_s).pose_world_body.translation().x(), fact("tunnel_end_x_m"));
}

TEST(SimProfiles, GarageDrivesUpItsRampsThroughIdenticalLevels) {
  const SimConfig cfg = default_config(Profile::Garage);
  const SequenceGenerator gen(cfg);
  const auto fact = [&](const char* key) { return std::stod(gen.description().at(key)); };
  const double level_m = fact("level_height_m");
  const Extremes e = sample(gen, cfg.duration_s);
  EXPECT_NEAR(e.standstill_s, 2.0, 0.05);
  EXPECT_LE(e.max_speed_m_s, 6.5);  // 6 m/s along the floor, a little more up a ramp
  EXPECT_NEAR(e.z_max_m - e.z_min_m, (fact("levels") - 1.0) * level_m, 1e-6);
  // The car drives on the scene's floors and ramps: the surface under the body is the body's
  // height below it (the ramps' inclined pieces follow the road to within a centimetre), and it
  // stays inside the garage's walls.
  const double body_height_m = e.z_min_m;
  for (double t = 0.0; t <= cfg.duration_s; t += 0.1) {
    const Eigen::Vector3d p = gen.state(cfg.start_stamp_ns + std::llround(t * 1e9)).pose_world_body.translation();
    const auto below = gen.scene().cast(p, -Eigen::Vector3d::UnitZ(), 10.0);
    ASSERT_TRUE(below) << t;
    EXPECT_NEAR(below->range_m, body_height_m, 0.01) << t;
    EXPECT_GT(p.x(), 0.0);
    EXPECT_LT(p.x(), 72.0);
    EXPECT_GT(p.y(), 0.0);
    EXPECT_LT(p.y(), 41.0);
  }
  // Levels 1 and 2 look the same from the inside: a ray from the same place at the LiDAR's height
  // above either floor returns the same range, unless it climbs through the ramp lane's openings
  // of two slabs (into level 3 from level 1, against the roof from level 2): 4 of 3528 rays.
  int rays = 0, same = 0;
  for (double x = 12.0; x <= 60.0; x += 8.0)
    for (int a = 0; a < 48; ++a)
      for (double elevation_deg = -24.0; elevation_deg <= 2.0; elevation_deg += 2.0) {
        const double az = 2.0 * M_PI * a / 48.0, el = elevation_deg * M_PI / 180.0;
        const Eigen::Vector3d dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        const auto one = gen.scene().cast(Eigen::Vector3d(x, 8.0, level_m + 1.8), dir, 120.0);
        const auto two = gen.scene().cast(Eigen::Vector3d(x, 8.0, 2.0 * level_m + 1.8), dir, 120.0);
        ASSERT_TRUE(one && two);
        same += std::abs(one->range_m - two->range_m) < 1e-9 ? 1 : 0;
        ++rays;
      }
  EXPECT_GT(rays, 3000);
  EXPECT_GE(same, rays - 10);
}

TEST(SimProfiles, GroundTruthTrajectories) {
  for (const Profile p : {Profile::Racetrack, Profile::Urban, Profile::Handheld, Profile::Tunnel, Profile::Garage}) {
    SimConfig cfg = default_config(p);
    cfg.duration_s = 3.0;
    const SequenceGenerator gen(cfg);
    const Trajectory body = gen.groundtruth_body(100.0);
    EXPECT_EQ(body.size(), 301U) << profile_name(p);
    EXPECT_TRUE(body.is_time_ordered());
    const Trajectory scans = gen.groundtruth_scans();
    ASSERT_EQ(scans.size(), gen.num_scans());
    EXPECT_EQ(gen.num_scans(), static_cast<std::size_t>(std::llround(3.0 * cfg.lidar_rate_hz))) << profile_name(p);
    for (std::size_t i = 0; i < scans.size(); ++i) {
      EXPECT_EQ(scans[i].stamp_ns, gen.scan_start_ns(i) + gen.scan_period_ns());
      EXPECT_LT((scans[i].pose.translation() - gen.state(scans[i].stamp_ns).pose_world_body.translation()).norm(),
                1e-12);
    }
  }
}

TEST(SimProfiles, VelocityIsTheDerivativeOfPosition) {
  // Central differences of the exact poses agree with the analytic velocity and rate.
  for (const Profile p : {Profile::Racetrack, Profile::Urban, Profile::Handheld, Profile::Tunnel, Profile::Garage}) {
    const SequenceGenerator gen(default_config(p));
    constexpr std::int64_t kStep_ns = 1'000'000;
    for (const double t : {0.3, 3.7, 11.1, 25.9, 47.3}) {
      const std::int64_t stamp = gen.config().start_stamp_ns + std::llround(t * 1e9);
      const BodyState s = gen.state(stamp), a = gen.state(stamp - kStep_ns), b = gen.state(stamp + kStep_ns);
      const Eigen::Vector3d v_fd = (b.pose_world_body.translation() - a.pose_world_body.translation()) / 2e-3;
      EXPECT_LT((v_fd - s.velocity_world_m_s).norm(), 1e-3 * (1.0 + s.velocity_world_m_s.norm()))
          << profile_name(p) << t;
      const Eigen::Vector3d acc_fd = (b.velocity_world_m_s - a.velocity_world_m_s) / 2e-3;
      EXPECT_LT((acc_fd - s.acceleration_world_m_s2).norm(), 1e-2) << profile_name(p) << t;
      const Eigen::Vector3d w_fd =
          so3_log(a.pose_world_body.rotation().transpose() * b.pose_world_body.rotation()) / 2e-3;
      EXPECT_LT((w_fd - s.angular_velocity_body_rad_s).norm(), 1e-3) << profile_name(p) << t;
    }
  }
}

TEST(SimProfiles, ALaterStartIsTheSameMotionFromThatInstant) {
  // motion_start_s = 12: t = 0 of the sequence is t = 12 of the profile (the racetrack at 70 m/s),
  // for the states, the ideal IMU and the scan-end ground truth; a negative start is refused
  SimConfig whole = default_config(Profile::Racetrack), cut = whole;
  whole.noise_free = cut.noise_free = true;
  whole.duration_s = 13.0;
  cut.duration_s = 1.0;
  cut.motion_start_s = 12.0;
  const SequenceGenerator a(whole), b(cut);
  const std::int64_t offset_ns = 12'000'000'000;
  for (const double t : {0.0, 0.37, 1.0}) {
    const std::int64_t stamp = cut.start_stamp_ns + std::llround(t * 1e9);
    const BodyState sa = a.state(stamp + offset_ns), sb = b.state(stamp);
    EXPECT_LT((sa.pose_world_body.translation() - sb.pose_world_body.translation()).norm(), 1e-9);
    EXPECT_LT((sa.velocity_world_m_s - sb.velocity_world_m_s).norm(), 1e-9);
  }
  EXPECT_NEAR(b.state(cut.start_stamp_ns).velocity_world_m_s.norm(), 70.0, 0.1);
  const auto imu_a = a.imu(), imu_b = b.imu();
  const std::size_t per_s = static_cast<std::size_t>(whole.imu_rate_hz);
  for (std::size_t k = 0; k < imu_b.size(); k += 97) {
    EXPECT_LT((imu_a[12 * per_s + k].accel_m_s2 - imu_b[k].accel_m_s2).norm(), 1e-9) << k;
    EXPECT_LT((imu_a[12 * per_s + k].gyro_rad_s - imu_b[k].gyro_rad_s).norm(), 1e-9) << k;
  }
  const auto gt_b = b.groundtruth_scans();
  EXPECT_LT((gt_b[0].pose.translation() - a.state(gt_b[0].stamp_ns + offset_ns).pose_world_body.translation()).norm(),
            1e-9);
  EXPECT_EQ(b.description().at("motion_start_s"), "12");
  cut.motion_start_s = -1.0;
  EXPECT_THROW(SequenceGenerator{cut}, std::invalid_argument);
}

TEST(SimConfigApi, ParseProfile) {
  EXPECT_EQ(parse_profile("racetrack"), Profile::Racetrack);
  EXPECT_EQ(parse_profile("urban"), Profile::Urban);
  EXPECT_EQ(parse_profile("handheld"), Profile::Handheld);
  EXPECT_EQ(parse_profile("tunnel"), Profile::Tunnel);
  EXPECT_EQ(parse_profile("garage"), Profile::Garage);
  try {
    (void)parse_profile("moon");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    for (const char* name : {"moon", "racetrack", "urban", "handheld", "tunnel", "garage"})
      EXPECT_NE(msg.find(name), std::string::npos);
  }
  for (const Profile p : {Profile::Racetrack, Profile::Urban, Profile::Handheld, Profile::Tunnel, Profile::Garage})
    EXPECT_EQ(parse_profile(profile_name(p)), p);
}

TEST(SimConfigApi, DefaultsDifferPerProfile) {
  const SimConfig race = default_config(Profile::Racetrack), urban = default_config(Profile::Urban),
                  hand = default_config(Profile::Handheld);
  EXPECT_EQ(race.lidar_rate_hz, 20.0);
  EXPECT_EQ(race.imu_rate_hz, 800.0);
  EXPECT_EQ(urban.lidar_rate_hz, 10.0);
  EXPECT_EQ(urban.imu_rate_hz, 100.0);
  EXPECT_EQ(hand.imu_rate_hz, 200.0);
  EXPECT_GT(race.noise.accel_noise_std_m_s2, urban.noise.accel_noise_std_m_s2);
  EXPECT_GT(race.noise.gyro_noise_std_rad_s, urban.noise.gyro_noise_std_rad_s);
  EXPECT_FALSE(race.noise_free);
  // The tunnel car carries the urban car's sensors.
  const SimConfig tunnel = default_config(Profile::Tunnel);
  EXPECT_EQ(tunnel.duration_s, 45.0);
  EXPECT_EQ(tunnel.lidar_rate_hz, urban.lidar_rate_hz);
  EXPECT_EQ(tunnel.imu_rate_hz, urban.imu_rate_hz);
  EXPECT_EQ(tunnel.noise.accel_noise_std_m_s2, urban.noise.accel_noise_std_m_s2);
  EXPECT_EQ(tunnel.noise.accel_bias_initial_m_s2, urban.noise.accel_bias_initial_m_s2);
}
