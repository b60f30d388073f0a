// The scan pipeline (LiDAR-only) on scans of a synthetic scene seen from a known trajectory.
#include <gtest/gtest.h>

#include "farlio/pipeline/scan_pipeline.hpp"
#include "scene_fixture.hpp"

using namespace farlio;

namespace {

// Sensor pose at time t: moving along x at 1.5 m/s, turning slowly, bobbing a little.
SE3 truth_at(double t) {
  Vec6d xi;
  xi << 0, 0, 0, 0.02 * std::sin(t), 0.0, 0.15 * t;
  return SE3(SE3::exp(xi).quaternion(), Eigen::Vector3d(-10.0 + 1.5 * t, 0.5 * std::sin(0.5 * t), 1.0));
}

Scan make_scan(int k, double period_s) {
  const double t = (k + 1) * period_s;
  const SE3 inv = truth_at(t).inverse();
  Scan s;
  s.end_stamp_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
  s.start_stamp_ns = s.end_stamp_ns - static_cast<std::int64_t>(std::llround(period_s * 1e9));
  for (const auto& p : test::sample_scene(80000, 100 + static_cast<unsigned>(k), 0.01f)) {
    s.points.push_back((inv * p.cast<double>()).cast<float>());
  }
  return s;
}

}  // namespace

TEST(ScanPipeline, TracksAKnownTrajectory) {
  const double period = 0.1;
  Config cfg;
  cfg.num_threads = 2;
  cfg.registration.time_budget_factor = 1e6;  // not a timing test (sanitizer builds are slow)
  pipeline::ScanPipeline p(cfg, truth_at(period));
  double worst_t = 0, worst_r = 0;
  for (int k = 0; k < 25; ++k) {
    const auto r = p.process(make_scan(k, period));
    const SE3 err = truth_at((k + 1) * period).inverse() * r.pose;
    worst_t = std::max(worst_t, err.translation().norm());
    worst_r = std::max(worst_r, err.angle_rad() * 180.0 / M_PI);
    EXPECT_EQ(r.registered, k > 0);
    if (k > 0) {
      EXPECT_TRUE(r.registration.converged) << "frame " << k;
    }
    EXPECT_GT(r.source_points, 500u);
    EXPECT_LE(r.timings.preprocess_s + r.timings.covariance_s + r.timings.registration_s + r.timings.map_update_s,
              r.timings.total_s + 1e-9);
  }
  EXPECT_LT(worst_t, 0.03);
  EXPECT_LT(worst_r, 0.15);
  // eq. (6): the body velocity of the last frames is ~1.5 m/s forward in the world
  const auto last = p.process(make_scan(25, period));
  const Eigen::Vector3d v_world = last.pose.rotation() * last.velocity_body_m_s;
  EXPECT_NEAR(v_world.x(), 1.5, 0.3);
  EXPECT_LE(p.backend().map_points(),
            p.backend().map_voxels() * static_cast<std::size_t>(cfg.map.max_points_per_voxel));
}

TEST(ScanPipeline, EmptyAndDegenerateScansDoNotCrash) {
  pipeline::ScanPipeline p(Config{});
  Scan empty;
  empty.end_stamp_ns = 100'000'000;
  const auto r0 = p.process(empty);
  EXPECT_FALSE(r0.registered);
  Scan nan;
  nan.end_stamp_ns = 200'000'000;
  nan.points.assign(100, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  const auto r1 = p.process(nan);
  EXPECT_EQ(r1.kept_points, 0u);
  EXPECT_TRUE(r1.pose.translation().allFinite());
}
