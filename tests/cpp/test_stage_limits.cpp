// The stage limits of farlio bench (pipeline/stage_limits.hpp): the yardstick kernels compute
// what they claim, the limits follow the documented work model and are finite for real frames.
// No timing is asserted (speed is measured by farlio bench, not by tests).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "farlio/pipeline/stage_limits.hpp"
#include "farlio/sim/sequence_generator.hpp"

namespace farlio::pipeline {
namespace {

TEST(StageLimits, TheDistanceKernelFindsTheBruteForceMinimum) {
  exec::CpuExecutor ex(2);
  std::vector<Eigen::Vector4f> points(37);  // not a multiple of the distance block
  for (auto& p : points) p = Eigen::Vector4f::Random();
  constexpr std::size_t kQueries = 100;
  float brute = std::numeric_limits<float>::max();
  for (std::size_t q = 0; q < kQueries; ++q) {
    const Eigen::Vector3f query = Eigen::Vector3f::Constant(static_cast<float>(q) * 1e-4f);
    for (const auto& p : points) brute = std::min(brute, (p.head<3>() - query).squaredNorm());
  }
  EXPECT_FLOAT_EQ(l1_distances_kernel(points, kQueries, ex), brute);
}

TEST(StageLimits, TheMemoryKernelSumsEveryElement) {
  exec::CpuExecutor ex(2);
  const std::vector<float> data(8 * 1024, 0.5f);
  EXPECT_FLOAT_EQ(memory_read_kernel(data, ex), 4096.0f);
}

TEST(StageLimits, FollowTheWorkModel) {
  FrameResult f;
  f.input_points = 100000;
  f.kept_points = 8000;
  f.source_points = 4000;
  f.registered = true;
  f.registration.iterations = 3;
  f.map_insert.candidates = 8000;
  f.map_insert.covariances_computed = 1000;
  const Yardsticks y{1, 1e10, 1e9};
  const int k = 10;
  const FrameTimings l = stage_limits(f, k, y);
  EXPECT_DOUBLE_EQ(l.preprocess_s, 28.0 * 100000 / 1e10);
  EXPECT_DOUBLE_EQ(l.covariance_s, 12.0 * 8000 / 1e10 + 4000.0 * k / 1e9 + 4000.0 * 220 / 8e9);
  EXPECT_DOUBLE_EQ(l.registration_s, 4000.0 / 1e9 + 3.0 * 4000 * 700 / 8e9);
  EXPECT_DOUBLE_EQ(l.map_update_s, (8000.0 + 1000.0 * k) / 1e9 + 1000.0 * 220 / 8e9);
  EXPECT_DOUBLE_EQ(l.total_s, l.preprocess_s + l.covariance_s + l.registration_s + l.map_update_s);
  // twice the rates: half the time; an unregistered frame has no registration work
  const FrameTimings fast = stage_limits(f, k, Yardsticks{1, 2e10, 2e9});
  EXPECT_NEAR(fast.total_s, 0.5 * l.total_s, 1e-15);
  f.registered = false;
  EXPECT_EQ(stage_limits(f, k, y).registration_s, 0.0);
}

TEST(StageLimits, RealFramesHaveFiniteLimitsInEveryStage) {
  exec::CpuExecutor ex(1);
  const Yardsticks y = measure_yardsticks(ex, 1);
  ASSERT_TRUE(std::isfinite(y.memory_read_bytes_per_s) && y.memory_read_bytes_per_s > 0.0);
  ASSERT_TRUE(std::isfinite(y.l1_distances_per_s) && y.l1_distances_per_s > 0.0);
  sim::SimConfig cfg = sim::default_config(sim::Profile::Urban);
  cfg.duration_s = 4.0;
  const sim::SequenceGenerator gen(cfg);
  Config config;
  config.num_threads = 1;
  ScanPipeline pipe(config);
  int checked = 0;
  for (std::size_t i = 0; i < gen.num_scans(); ++i) {
    const FrameResult r = pipe.process(gen.scan(i));
    if (!r.registered) continue;
    const FrameTimings l = stage_limits(r, config.map.covariance_neighbors, y);
    for (const double s : {l.preprocess_s, l.covariance_s, l.registration_s, l.map_update_s}) {
      EXPECT_TRUE(std::isfinite(s) && s > 0.0) << "scan " << i;
    }
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

}  // namespace
}  // namespace farlio::pipeline
