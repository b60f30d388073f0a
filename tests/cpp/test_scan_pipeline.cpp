// The scan pipeline (LiDAR-only) on scans of a synthetic scene seen from a known trajectory.
#include <gtest/gtest.h>

#include <limits>

#include "farlio/pipeline/cpu_scan_backend.hpp"
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
  return test::scene_scan(truth_at(t), t, period_s, 80000, 100 + static_cast<unsigned>(k), 0.01f);
}

double translation_error_m(const SE3& a, const SE3& b) { return (a.inverse() * b).translation().norm(); }

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

TEST(ScanPipeline, SourceWithoutCovariancesHasTheSamePointsAndDensity) {
  // the first scan (no submap yet) builds its source without covariances: nothing reads them,
  // and the points and the density (the map's limit) are those of the full source
  Config cfg;
  cfg.num_threads = 2;
  pipeline::CpuScanBackend backend(cfg);
  const Scan scan = make_scan(0, 0.1);
  ASSERT_GT(backend.preprocess(scan, deskew::ScanMotion{}, false), 1000u);
  const pipeline::SourceSummary without = backend.build_source(cfg.density.close_range_m, false);
  const pipeline::SourceSummary with = backend.build_source(cfg.density.close_range_m, true);
  EXPECT_GT(with.points, 500u);
  EXPECT_EQ(without.points, with.points);
  EXPECT_EQ(without.mean_points_per_voxel, with.mean_points_per_voxel);
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

TEST(ScanPipeline, TheBackendDropsNonFinitePointsAsTheScanDoes) {
  // the backend screens the scan in its first pass (the pipeline leaves it to it after the first
  // scan): the same frame and the same count as Scan::remove_non_finite before a clean pass
  Config cfg;
  cfg.num_threads = 2;
  pipeline::CpuScanBackend screening(cfg), clean(cfg);
  Scan bad = make_scan(3, 0.1);
  bad.start_stamp_ns = bad.end_stamp_ns - seconds_to_ns(0.1);
  for (std::size_t i = 0; i < bad.size(); ++i) bad.time_s.push_back(static_cast<float>(0.1 * i / bad.size()));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < bad.size(); i += 53) bad.points[i].y() = nan;
  for (std::size_t i = 7; i < bad.size(); i += 71) bad.points[i].z() = -inf;
  for (std::size_t i = 11; i < bad.size(); i += 61) bad.time_s[i] = nan;
  Scan dropped = bad;
  const std::size_t removed = dropped.remove_non_finite();
  ASSERT_GT(removed, bad.size() / 40);
  const deskew::ScanMotion motion = deskew::ScanMotion::constant_twist(deskew::Vec6f::Constant(0.3f), 0.1f);
  EXPECT_EQ(screening.preprocess(bad, motion, true), clean.preprocess(dropped, motion, true));
  EXPECT_EQ(screening.non_finite_points(), removed);
  EXPECT_EQ(clean.non_finite_points(), 0u);
  EXPECT_EQ(screening.frame_points(), clean.frame_points());
}

TEST(ScanPipeline, PointsWithNonFiniteTimesAreDroppedAsTheReadersDo) {
  // a scan handed to the API with NaN or Inf per-point times (the readers drop such points):
  // those points are dropped and counted, and the pose is that of the scan without them
  const double period = 0.1;
  Config cfg = Config{};
  cfg.num_threads = 2;
  cfg.registration.time_budget_factor = 1e6;
  pipeline::ScanPipeline with_bad(cfg, truth_at(period)), clean(cfg, truth_at(period));
  for (int k = 0; k < 4; ++k) {
    Scan scan = make_scan(k, period);
    scan.start_stamp_ns = scan.end_stamp_ns - seconds_to_ns(period);
    for (std::size_t i = 0; i < scan.size(); ++i) scan.time_s.push_back(static_cast<float>(period * i / scan.size()));
    Scan bad = scan;
    std::size_t marked = 0;
    for (std::size_t i = k; i < bad.size(); i += 97, ++marked) {
      bad.time_s[i] = (i % 2 == 0) ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
    }
    Scan dropped = bad;
    ASSERT_EQ(dropped.remove_non_finite(), marked);
    const auto r = with_bad.process(bad);
    const auto c = clean.process(dropped);
    EXPECT_EQ(r.non_finite_points, marked);
    EXPECT_EQ(r.input_points, scan.size());
    EXPECT_TRUE(r.pose.translation().allFinite());
    EXPECT_LT(translation_error_m(r.pose, c.pose), 1e-9) << "frame " << k;
  }
}

namespace {

/// A scan at frame k's stamps whose points are `points` (sensor frame).
Scan scan_with_points(int k, double period_s, std::vector<Eigen::Vector3f> points) {
  Scan s = make_scan(k, period_s);
  s.points = std::move(points);
  return s;
}

}  // namespace

// A scan of 3 points, or of one point repeated, could "converge" with a single inlier and move the
// pose by metres: it fails, keeps the prediction and changes neither the map nor the adaptive
// threshold, and the next good scan registers as before.
TEST(ScanPipeline, ADegenerateScanFailsKeepsThePredictionAndChangesNothing) {
  const double period = 0.1;
  Config cfg;
  cfg.num_threads = 2;
  cfg.registration.time_budget_factor = 1e6;
  const std::vector<std::vector<Eigen::Vector3f>> bad_scans = {
      {{3.0f, 1.0f, 0.5f}, {-2.0f, 4.0f, 1.0f}, {5.0f, -3.0f, 0.2f}},         // 3 points
      std::vector<Eigen::Vector3f>(5000, Eigen::Vector3f(4.0f, 2.0f, 1.0f)),  // one point repeated
  };
  for (const auto& bad : bad_scans) {
    pipeline::ScanPipeline p(cfg, truth_at(period));
    for (int k = 0; k < 5; ++k) p.process(make_scan(k, period));
    const std::size_t map_points = p.backend().map_points();
    const SE3 predicted = p.predict(make_scan(5, period).end_stamp_ns);
    const auto r = p.process(scan_with_points(5, period, bad));
    EXPECT_TRUE(r.registered);
    EXPECT_FALSE(r.failure.empty()) << bad.size() << " points";
    EXPECT_NE(r.failure.find("too few inliers"), std::string::npos) << r.failure;
    EXPECT_LT(translation_error_m(r.pose, predicted), 1e-9);  // the prediction, untouched
    EXPECT_EQ(p.backend().map_points(), map_points);          // the map is unchanged
    EXPECT_FALSE(r.map_restarted);
    // the next good scan tracks as before: the threshold and the motion model are intact
    const auto next = p.process(make_scan(6, period));
    EXPECT_TRUE(next.failure.empty()) << next.failure;
    EXPECT_LT(translation_error_m(next.pose, truth_at(7 * period)), 0.03);
    EXPECT_EQ(next.sigma_m, r.sigma_m);  // the failed scan did not update the threshold
  }
}

// The Cauchy kernel scale: sigma / 3 (KISS-ICP) with the constant-velocity guess, at most
// registration.fused_kernel_scale_m with a guess from another sensor (the fusion's), at most
// confirmed_kernel_scale_m once that guess is confirmed (frames 8-12), never wider; a LiDAR-only
// guess keeps sigma / 3 even when called confirmed.
TEST(ScanPipeline, AGuessFromTheFusionCapsTheKernelScale) {
  const double period = 0.1;
  for (const double cap_m : {0.2, 10.0}) {
    Config cfg;
    cfg.num_threads = 2;
    cfg.registration.time_budget_factor = 1e6;
    cfg.registration.fused_kernel_scale_m = cap_m;
    cfg.registration.confirmed_kernel_scale_m = 0.5 * cap_m;
    pipeline::ScanPipeline p(cfg, truth_at(period));
    for (int k = 0; k < 3; ++k) {
      const auto r = p.process(make_scan(k, period));
      if (k > 0) EXPECT_DOUBLE_EQ(r.kernel_scale_m, r.sigma_m / 3.0) << "constant velocity, frame " << k;
    }
    for (int k = 3; k < 13; ++k) {
      const bool confirmed = k >= 8;
      const SE3 guess = truth_at((k + 1) * period);
      const auto r = p.process(make_scan(k, period), guess, std::nullopt, true, confirmed);
      ASSERT_TRUE(r.failure.empty()) << r.failure;
      EXPECT_DOUBLE_EQ(r.kernel_scale_m, std::min(r.sigma_m / 3.0, confirmed ? 0.5 * cap_m : cap_m))
          << "fusion's guess, frame " << k;
      EXPECT_LT(translation_error_m(r.pose, guess), 0.03);
    }
    const auto r = p.process(make_scan(13, period), truth_at(14 * period), std::nullopt, false, true);
    EXPECT_DOUBLE_EQ(r.kernel_scale_m, r.sigma_m / 3.0) << "a LiDAR-only guess";
  }
}

// Recovery: when registrations fail for map_restart_after_s (the old map no longer matches), the
// map restarts from the current scan at the prediction, and tracking resumes from there.
TEST(ScanPipeline, PersistentFailuresRestartTheMapAndTrackingResumes) {
  const double period = 0.1;
  Config cfg;
  cfg.num_threads = 2;
  cfg.registration.time_budget_factor = 1e6;
  cfg.registration.map_restart_after_s = 0.25;
  pipeline::ScanPipeline p(cfg, truth_at(period));
  for (int k = 0; k < 4; ++k) p.process(make_scan(k, period));
  // a patch of a plane 40 m above the scene: no map point within the correspondence distance
  constexpr int kSide = 40;
  constexpr float kStep_m = 0.5f;
  std::vector<Eigen::Vector3f> far;
  for (int i = 0; i < kSide * kSide; ++i) {
    far.emplace_back(30.0f + kStep_m * static_cast<float>(i % kSide), kStep_m * static_cast<float>(i / kSide - 20),
                     40.0f);
  }
  bool restarted = false;
  int k = 4;
  for (; k < 10 && !restarted; ++k) {
    const auto r = p.process(scan_with_points(k, period, far));
    EXPECT_FALSE(r.failure.empty());
    EXPECT_TRUE(r.pose.translation().allFinite());
    restarted = r.map_restarted;
  }
  EXPECT_TRUE(restarted);
  EXPECT_EQ(k - 1, 7);  // failures from k = 4 (0.5 s) on: k = 7 is the first 0.25 s or more after it
  EXPECT_GT(p.backend().map_points(), 0u);
  // the restarted map holds the new scene: the next scan of it registers
  const auto next = p.process(scan_with_points(k, period, far));
  EXPECT_TRUE(next.failure.empty()) << next.failure;
  EXPECT_FALSE(next.map_restarted);
}

// A scan that sees more new space than mapped space (most of its points where the map has nothing:
// a narrow field of view turning into a room) fails registration.min_inlier_fraction from the
// constant-velocity guess, where it could as well be a scan of something else; from the fusion's
// guess the registration stands (the fusion's gate judges it) and the map grows by the new space.
TEST(ScanPipeline, FromTheFusionsGuessAScanOfMostlyNewSpaceIsNoFailure) {
  const double period = 0.1;
  for (const bool from_fusion : {false, true}) {
    Config cfg;
    cfg.num_threads = 2;
    cfg.registration.time_budget_factor = 1e6;
    pipeline::ScanPipeline p(cfg, truth_at(period));
    for (int k = 0; k < 4; ++k) p.process(make_scan(k, period));
    const std::size_t voxels_before = p.backend().map_voxels();
    // the scene's scan and a ceiling 30 m above the sensor, 80 m by 80 m, that the map has never
    // seen (the scene is 8 m high)
    Scan scan = make_scan(4, period);
    constexpr float kStep_m = 0.25f;
    for (float x = -40.0f; x <= 40.0f; x += kStep_m) {
      for (float y = -40.0f; y <= 40.0f; y += kStep_m) {
        scan.points.emplace_back(x, y, 30.0f);
        if (scan.has_time()) scan.time_s.push_back(static_cast<float>(period / 2));
      }
    }
    const SE3 truth = truth_at(5 * period);
    const auto r = p.process(scan, truth, std::nullopt, from_fusion, true);
    ASSERT_TRUE(r.registered);
    EXPECT_LT(r.inlier_fraction, cfg.registration.min_inlier_fraction) << "the scan must see mostly new space";
    if (from_fusion) {
      EXPECT_TRUE(r.failure.empty()) << r.failure;
      EXPECT_LT(translation_error_m(r.pose, truth), 0.03);
      EXPECT_GT(p.backend().map_voxels(), voxels_before + 300);  // the ceiling's cells
    } else {
      EXPECT_NE(r.failure.find("registration.min_inlier_fraction"), std::string::npos) << r.failure;
      EXPECT_EQ(p.backend().map_voxels(), voxels_before);
    }
  }
}
