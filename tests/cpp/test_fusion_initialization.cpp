// The LiDAR-inertial alignment that initialises the filter (fusion/initialization.hpp): gravity
// in the map frame and the velocity from a window of poses and the IMU between them, against the
// generator's exact motion, at rest and in motion, with gravity known or not.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "farlio/core/time.hpp"
#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/imu_buffer.hpp"
#include "farlio/fusion/initialization.hpp"
#include "farlio/sim/sequence_generator.hpp"

namespace farlio {
namespace {

using fusion::AlignmentOptions;
using fusion::ImuMean;
using fusion::WindowPose;

constexpr double kRadToDeg = 180.0 / M_PI;

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * kRadToDeg;
}

/// A window of a generated recording: poses in a map frame that is the world turned by `map_from_world`
/// (so that the map is not level), the IMU as the filter reads it.
struct Window {
  std::vector<WindowPose> poses;
  fusion::ImuBuffer imu{0.1, 10.0};
  SE3 map_from_world;
  Eigen::Vector3d true_gravity_map;
  Eigen::Vector3d true_velocity_map;  ///< at the last pose

  fusion::ImuMeanFn mean() const {
    return [this](std::int64_t t0, std::int64_t t1) -> std::optional<ImuMean> {
      const fusion::ImuReading r = imu.mean(t0, t1);
      if (r.in_gap) return std::nullopt;
      return ImuMean{r.accel, r.gyro_rad_s};
    };
  }
};

Window make_window(const std::string& profile, double motion_start_s, double span_s, bool noise_free,
                   double pose_noise_m = 0.0, unsigned seed = 1) {
  sim::SimConfig cfg = sim::default_config(sim::parse_profile(profile));
  cfg.motion_start_s = motion_start_s;
  cfg.duration_s = span_s + 0.5;
  cfg.noise_free = noise_free;
  const sim::SequenceGenerator gen(cfg);
  Window w;
  w.map_from_world =
      SE3(fusion::rotation_from_euler(Eigen::Vector3d(0.2, -0.15, 0.7)), Eigen::Vector3d(3.0, -2.0, 1.0));
  for (const ImuSample& s : gen.imu()) w.imu.push(s);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, pose_noise_m);
  const std::int64_t period = gen.scan_period_ns();
  for (std::int64_t t = cfg.start_stamp_ns + period; t <= cfg.start_stamp_ns + seconds_to_ns(span_s); t += period) {
    SE3 pose = w.map_from_world * gen.state(t).pose_world_body;
    if (pose_noise_m > 0.0)
      pose = SE3(pose.rotation(), pose.translation() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    w.poses.push_back({t, pose, {}});
  }
  const Eigen::Matrix3d R = w.map_from_world.rotation();
  w.true_gravity_map = R * Eigen::Vector3d(0, 0, -cfg.gravity_m_s2);
  w.true_velocity_map = R * gen.state(w.poses.back().stamp_ns).velocity_world_m_s;
  return w;
}

struct Case {
  const char* profile;
  double motion_start_s;
};

class AlignmentInMotion : public ::testing::TestWithParam<Case> {};

// Exact poses and an ideal IMU: the equations hold up to the integration, so gravity and the
// velocity come out exact, at any motion.
TEST_P(AlignmentInMotion, ExactPosesAndIdealImuGiveGravityAndVelocity) {
  const Window w = make_window(GetParam().profile, GetParam().motion_start_s, 0.5, /*noise_free=*/true);
  const auto a = fusion::align_window(w.poses, w.mean(), AlignmentOptions{});
  ASSERT_TRUE(a.has_value());
  EXPECT_LT(angle_deg(a->gravity_map_m_s2, w.true_gravity_map), 0.02);
  EXPECT_NEAR(a->gravity_map_m_s2.norm(), 9.81, 1e-9);
  EXPECT_LT((a->velocity_map_m_s - w.true_velocity_map).norm(), 0.01) << a->velocity_map_m_s.transpose();
  EXPECT_LT(a->gravity_norm_error, 0.002);
  EXPECT_LT(a->position_residual_m, 1e-3);
}

INSTANTIATE_TEST_SUITE_P(Profiles, AlignmentInMotion,
                         ::testing::Values(Case{"racetrack", 12.0}, Case{"racetrack", 30.0}, Case{"urban", 10.0},
                                           Case{"urban", 30.0}, Case{"handheld", 8.0}, Case{"tunnel", 8.0}));

}  // namespace
}  // namespace farlio
