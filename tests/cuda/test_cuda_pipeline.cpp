// The scan pipeline on the GPU against the CPU over 100 generated urban frames, its
// preallocation, its device timings, and a scan that does not fit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cuda_test_support.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "farlio/sim/sequence_generator.hpp"
#include "sim_recording.hpp"

using namespace farlio;

namespace {

constexpr std::size_t kFrames = 100;
constexpr std::size_t kSkipAtRest = 25;  // generated urban starts with 2 s at rest
// Agreement bounds. Both backends run the same bodies, the GICP systems with the same
// correspondence reuse; what may still differ is the reductions' summation order and libdevice's
// sin/cos against glibc's in the undistortion (a point may fall into a neighbouring cell).
// Measured on an H100 (scripts/gpu_check.sh): 1.6e-14 m and 3e-15 deg over these 100 frames. The
// bounds leave room for a card or driver on which a point does change cells (docs/cuda.md).
constexpr double kMaxTranslationDiff_m = 0.001;
constexpr double kMaxRotationDiff_deg = 0.003;
constexpr std::size_t kDeviceMemoryLimitBytes = std::size_t{1} << 30;  // the 1 GB

Config config_on(Device d) {
  Config c;
  c.device = d;
  c.registration.time_budget_factor = 1e6;  // compare results, not the time budget
  return c;
}

}  // namespace

TEST(CudaPipeline, HundredUrbanFramesAgreeWithTheCpu) {
  FARLIO_REQUIRE_GPU();
  sim::SimConfig sc = sim::default_config(sim::Profile::Urban);
  sc.duration_s = 0.1 * static_cast<double>(kSkipAtRest + kFrames + 1);
  const sim::SequenceGenerator gen(sc);
  pipeline::ScanPipeline cpu(config_on(Device::Cpu)), gpu(config_on(Device::Cuda));
  ASSERT_EQ(gpu.backend().device(), Device::Cuda);
  double worst_t = 0, worst_r = 0;
  for (std::size_t i = kSkipAtRest; i < kSkipAtRest + kFrames; ++i) {
    const Scan scan = gen.scan(i);
    const auto rc = cpu.process(scan);
    const auto rg = gpu.process(scan);
    const SE3 d = rc.pose.inverse() * rg.pose;
    worst_t = std::max(worst_t, d.translation().norm());
    worst_r = std::max(worst_r, d.angle_rad() * 180.0 / M_PI);
    EXPECT_EQ(rc.registered, rg.registered);
    EXPECT_NEAR(static_cast<double>(rg.kept_points), static_cast<double>(rc.kept_points), 0.01 * rc.kept_points);
    EXPECT_TRUE(rg.timings.device_timed);
    EXPECT_GT(rg.timings.preprocess_s, 0.0);
  }
  std::printf("CPU/GPU agreement over %zu urban frames: %.2e m, %.2e deg\n", kFrames, worst_t, worst_r);
  EXPECT_LT(worst_t, kMaxTranslationDiff_m);
  EXPECT_LT(worst_r, kMaxRotationDiff_deg);
  EXPECT_NEAR(static_cast<double>(gpu.backend().map_points()), static_cast<double>(cpu.backend().map_points()),
              0.01 * static_cast<double>(cpu.backend().map_points()));
}

TEST(CudaPipeline, DefaultPreallocationFitsTheMemoryBudget) {
  FARLIO_REQUIRE_GPU();
  const pipeline::ScanPipeline gpu(config_on(Device::Cuda));
  std::printf("CUDA backend preallocates %.1f MiB\n", static_cast<double>(gpu.backend().memory_bytes()) / (1 << 20));
  EXPECT_LT(gpu.backend().memory_bytes(), kDeviceMemoryLimitBytes);
}

TEST(CudaPipeline, AScanBeyondTheBuffersIsACapacityErrorNamingTheParameter) {
  FARLIO_REQUIRE_GPU();
  Config c = config_on(Device::Cuda);
  c.cuda.max_scan_points = 1000;
  pipeline::ScanPipeline gpu(c);
  Scan scan;
  scan.end_stamp_ns = 100'000'000;
  scan.points.assign(2000, Eigen::Vector3f(5.0f, 1.0f, 0.0f));
  try {
    gpu.process(scan);
    FAIL() << "expected CapacityError";
  } catch (const CapacityError& e) {
    EXPECT_NE(std::string(e.what()).find("cuda.max_scan_points"), std::string::npos) << e.what();
  }
}

TEST(CudaPipeline, AutoPicksTheGpu) {
  FARLIO_REQUIRE_GPU();
  std::string message;
  EXPECT_EQ(resolve_device(Device::Auto, &message), Device::Cuda);
  const pipeline::ScanPipeline p(Config{});
  EXPECT_EQ(p.backend().device(), Device::Cuda);
}

TEST(CudaPipeline, FewFramesRunEveryKernel) {
  // short enough for compute-sanitizer (scripts/gpu_check.sh): every stage's kernels, with
  // undistortion (per-point times) and a registration per frame
  FARLIO_REQUIRE_GPU();
  constexpr std::size_t kFewFrames = 4;
  sim::SimConfig sc = sim::default_config(sim::Profile::Urban);
  sc.duration_s = 0.1 * static_cast<double>(kSkipAtRest + kFewFrames + 1);
  const sim::SequenceGenerator gen(sc);
  pipeline::ScanPipeline gpu(config_on(Device::Cuda));
  for (std::size_t i = kSkipAtRest; i < kSkipAtRest + kFewFrames; ++i) {
    const auto r = gpu.process(gen.scan(i));
    EXPECT_EQ(r.registered, i > kSkipAtRest);
    EXPECT_GT(r.source_points, 0u);
    EXPECT_GT(r.map_insert.covariances_computed, 0u);
  }
  EXPECT_GT(gpu.backend().map_points(), 0u);
}

TEST(CudaPipeline, EmptyTinyAndNonFiniteScansGoAsOnTheCpu) {
  // bad input on the device path: an empty scan, three points, and a scan with half its points
  // NaN or infinite and some of the others with a NaN time, among good scans; the same outcome as
  // the CPU's (the GPU drops and counts the non-finite points itself), no device error
  FARLIO_REQUIRE_GPU();
  constexpr std::size_t kGood = 10, kEmpty = 3, kTiny = 5, kNonFinite = 7, kTinyPoints = 3, kNanTimeEvery = 8;
  constexpr double kMaxPoseDiff_m = 0.01;
  sim::SimConfig sc = sim::default_config(sim::Profile::Urban);
  sc.duration_s = 0.1 * static_cast<double>(kSkipAtRest + kGood + 1);
  const sim::SequenceGenerator gen(sc);
  pipeline::ScanPipeline cpu(config_on(Device::Cpu)), gpu(config_on(Device::Cuda));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (std::size_t k = 0; k < kGood; ++k) {
    Scan scan = gen.scan(kSkipAtRest + k);
    if (k == kEmpty) {
      scan.points.clear();
      scan.time_s.clear();
      scan.intensity.clear();
      scan.sensor_id.clear();
    } else if (k == kTiny) {
      scan = test::thinned(scan, scan.size() / kTinyPoints);
    } else if (k == kNonFinite) {
      for (std::size_t i = 0; i < scan.size(); i += 2) scan.points[i] = Eigen::Vector3f(nan, 1.0f, inf);
      for (std::size_t i = 1; i < scan.size(); i += kNanTimeEvery) scan.time_s[i] = nan;
    }
    const auto rc = cpu.process(scan);
    const auto rg = gpu.process(scan);
    SCOPED_TRACE("scan " + std::to_string(k));
    const bool bad = k == kEmpty || k == kTiny;
    EXPECT_EQ(rc.failure.empty(), !bad) << rc.failure;  // the CPU's verdict: what the GPU must match
    if (k == kNonFinite) {
      EXPECT_TRUE(rc.registered);  // half of it is a good scan
      const std::size_t n = scan.size();
      EXPECT_EQ(rc.non_finite_points, (n + 1) / 2 + (n - 1 + kNanTimeEvery - 1) / kNanTimeEvery);
    }
    EXPECT_EQ(rc.non_finite_points, rg.non_finite_points);
    EXPECT_EQ(rc.registered, rg.registered);
    EXPECT_EQ(rc.failure, rg.failure);
    // libdevice's sin/cos in the undistortion may move a point into a neighbouring cell
    EXPECT_NEAR(static_cast<double>(rg.kept_points), static_cast<double>(rc.kept_points), 0.01 * rc.kept_points);
    EXPECT_TRUE(rg.pose.translation().allFinite());
    EXPECT_LT((rc.pose.translation() - rg.pose.translation()).norm(), kMaxPoseDiff_m);
  }
  EXPECT_NEAR(static_cast<double>(gpu.backend().map_points()), static_cast<double>(cpu.backend().map_points()),
              0.01 * static_cast<double>(cpu.backend().map_points()));
}

namespace {

/// The frames' poses and the submap of `p` equal those of `q` exactly (the same kernels on the
/// same data: the results are the same bits).
void expect_same_map(const pipeline::ScanPipeline& p, const pipeline::ScanPipeline& q) {
  const map::MapSnapshot a = p.backend().map_snapshot(), b = q.backend().map_snapshot();
  EXPECT_EQ(a.voxel_keys, b.voxel_keys);
  EXPECT_EQ(a.voxel_counts, b.voxel_counts);
  EXPECT_TRUE(a.points == b.points);
}

void expect_same_pose(const pipeline::FrameResult& a, const pipeline::FrameResult& b) {
  EXPECT_EQ(a.pose.translation(), b.pose.translation());
  EXPECT_EQ(a.pose.rotation(), b.pose.rotation());
  EXPECT_EQ(a.kept_points, b.kept_points);
  EXPECT_EQ(a.source_points, b.source_points);
}

}  // namespace

TEST(CudaPipeline, ScansStagedBackToBackGiveTheSameBitsAsScansUploadedInTheirFrame) {
  // offline use: the next scan is staged before each frame, so its upload overlaps the frame's
  // kernels; every scan after the first must be found staged, and nothing may change
  FARLIO_REQUIRE_GPU();
  constexpr std::size_t kStagedFrames = 12;
  const std::vector<Scan> scans = test::generated_scans(sim::Profile::Urban, kSkipAtRest, kStagedFrames);
  pipeline::ScanPipeline plain(config_on(Device::Cuda)), staged(config_on(Device::Cuda));
  for (std::size_t i = 0; i < scans.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    if (i + 1 < scans.size()) staged.stage_next(scans[i + 1]);
    const auto a = plain.process(scans[i]);
    const auto b = staged.process(scans[i]);
    EXPECT_FALSE(plain.backend().last_scan_was_staged());
    EXPECT_EQ(staged.backend().last_scan_was_staged(), i > 0);
    expect_same_pose(a, b);
  }
  expect_same_map(plain, staged);
}

TEST(CudaPipeline, AScanOtherThanTheStagedOnesIsUploadedInItsFrame) {
  // staging out of step with processing: a scan processed without staging, three scans staged
  // ahead (with two slots, the older staged scan gives way), a copy of a scan staged instead of
  // the scan itself, a scan staged twice; each scan still gives the bits of a plain run, and is
  // found staged only when the object itself was staged and is still held
  FARLIO_REQUIRE_GPU();
  constexpr std::size_t kScans = 8;
  const std::vector<Scan> s = test::generated_scans(sim::Profile::Urban, kSkipAtRest, kScans);
  pipeline::ScanPipeline plain(config_on(Device::Cuda)), staged(config_on(Device::Cuda));
  const auto step = [&](std::size_t k, bool expect_staged) {
    SCOPED_TRACE("scan " + std::to_string(k));
    const auto a = plain.process(s[k]);
    const auto b = staged.process(s[k]);
    EXPECT_EQ(staged.backend().last_scan_was_staged(), expect_staged);
    expect_same_pose(a, b);
  };
  staged.stage_next(s[1]);
  step(0, false);  // s1 waits staged
  staged.stage_next(s[2]);
  step(1, true);
  staged.stage_next(s[3]);  // s2 and s3 wait staged
  staged.stage_next(s[4]);  // both slots hold one: s2, the older, is dropped
  step(2, false);           // uploaded in its frame, into s3's slot (now the older)
  step(3, false);
  step(4, true);
  const Scan copy = s[5];  // the same points in another object: not the scan staged
  staged.stage_next(copy);
  step(5, false);
  staged.stage_next(s[6]);
  staged.stage_next(s[6]);  // twice: either copy serves
  step(6, true);
  step(7, false);
  expect_same_map(plain, staged);
}
