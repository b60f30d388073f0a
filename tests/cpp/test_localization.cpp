// Localization in a prior map held fixed (ScanPipeline::set_prior_map), LiDAR-only, on scans of
// a synthetic scene from a known trajectory.
#include <gtest/gtest.h>

#include <cmath>

#include "farlio/pipeline/scan_pipeline.hpp"
#include "scene_fixture.hpp"

using namespace farlio;

namespace {

constexpr double kPeriod_s = 0.1;

SE3 truth_at(double t) {
  Vec6d xi;
  xi << 0, 0, 0, 0.0, 0.0, 0.2 * t;
  return SE3(SE3::exp(xi).quaternion(), Eigen::Vector3d(-8.0 + 2.0 * t, 0.3 * std::sin(t), 1.5));
}

Scan make_scan(int k) {
  const double t = (k + 1) * kPeriod_s;
  return test::scene_scan(truth_at(t), t, kPeriod_s, 60000, 500 + static_cast<unsigned>(k), 0.01f);
}

Config test_config() {
  Config cfg;
  cfg.num_threads = 2;
  cfg.registration.time_budget_factor = 1e6;  // not a timing test (sanitizer builds are slow)
  return cfg;
}

/// The prior map: the scene sampled densely (another sample than the scans', no noise).
std::vector<Eigen::Vector3f> prior_map() { return test::sample_scene(150000, 1, 0.0f); }

SE3 offset(double dx, double dy, double yaw_deg) {
  Vec6d xi;
  xi << dx, dy, 0, 0, 0, yaw_deg * M_PI / 180.0;
  return SE3::exp(xi);
}

}  // namespace

TEST(Localization, TracksInAFixedPriorMapFromAnOffStart) {
  pipeline::ScanPipeline p(test_config(), truth_at(kPeriod_s) * offset(0.4, -0.3, 3.0));
  p.set_prior_map(prior_map());
  EXPECT_TRUE(p.localizing());
  std::size_t map_points = 0;
  double worst_t = 0, worst_r = 0;
  for (int k = 0; k < 20; ++k) {
    const auto r = p.process(make_scan(k));
    EXPECT_TRUE(r.registered) << "frame " << k;  // even the first scan: the map is there
    EXPECT_FALSE(r.lost) << "frame " << k << ": " << r.failure;
    EXPECT_GT(r.inlier_fraction, 0.9) << "frame " << k;
    if (k == 0) map_points = r.map_points;
    EXPECT_EQ(r.map_points, map_points) << "the prior map is held fixed";
    EXPECT_EQ(r.map_insert.inserted, 0u);
    const SE3 err = truth_at((k + 1) * kPeriod_s).inverse() * r.pose;
    worst_t = std::max(worst_t, err.translation().norm());
    worst_r = std::max(worst_r, err.angle_rad() * 180.0 / M_PI);
  }
  EXPECT_GT(map_points, 5000u);
  EXPECT_LT(worst_t, 0.03);
  EXPECT_LT(worst_r, 0.15);
}

TEST(Localization, AStartFarOffIsLost) {
  // 30 m off: the sensor believes it is outside the mapped room
  pipeline::ScanPipeline p(test_config(), truth_at(kPeriod_s) * offset(30.0, 0.0, 0.0));
  p.set_prior_map(prior_map());
  int lost = 0;
  for (int k = 0; k < 10; ++k) {
    const auto r = p.process(make_scan(k));
    lost += r.lost ? 1 : 0;
    if (r.lost) {
      EXPECT_FALSE(r.failure.empty());
    }
  }
  EXPECT_EQ(lost, 10);
}

TEST(Localization, OdometryWithoutAPriorMapIsNeverLost) {
  pipeline::ScanPipeline p(test_config(), truth_at(kPeriod_s));
  EXPECT_FALSE(p.localizing());
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(p.process(make_scan(k)).lost);
  EXPECT_THROW(p.set_prior_map(prior_map()), std::logic_error);
}
