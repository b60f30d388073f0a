// The whole LiDAR-inertial odometry (the EKF at 100 Hz, the IMU-predicted guesses and
// undistortion, the scan pipeline) with the scan pipeline on the GPU, against the same replay on
// the CPU: generated urban and racetrack recordings, full scans, no time budget and zero latency
// (so that neither run depends on how fast its device is).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "cuda_test_support.hpp"
#include "farlio/pipeline/odometry.hpp"
#include "sim_recording.hpp"

using namespace farlio;

namespace {

constexpr double kDuration_s = 10.0;
constexpr std::size_t kAllPoints = 1;
// How far the GPU run's scan poses may stray from the CPU run's, and how much more its final
// position may be off the ground truth. Measured on an H100 (scripts/gpu_check.sh): urban 3e-14 m,
// racetrack (200 scans at racing speed) 1.8e-12 m, the same final errors (0.013 m, 0.215 m): the
// backends run the same bodies, the GICP systems with the same correspondence reuse. The bounds
// leave room for the summation order and libdevice's sin/cos on other cards (docs/cuda.md).
constexpr double kMaxPoseDiff_m = 0.005;
constexpr double kMaxPoseDiff_deg = 0.01;
constexpr double kMaxExtraFinalError_m = 0.005;

struct ReplayRun {
  std::vector<SE3> poses;  ///< body poses at the scan ends, relative to the first
  std::size_t fused = 0;
};

ReplayRun replay(const test::Recording& rec, Device device) {
  Config config = test::deterministic_config();
  config.device = device;
  pipeline::ReplayOptions zero;
  zero.latency = pipeline::LatencyModel::Zero;
  pipeline::Odometry odo(config, rec.T_imu_lidar, rec.gravity_m_s2, rec.imu, zero);
  ReplayRun r;
  SE3 first;
  for (std::size_t i = 0; i < rec.scans.size(); ++i) {
    const auto f = odo.process(rec.scans[i]);
    if (i == 0) first = f.body_pose;
    r.poses.push_back(first.inverse() * f.body_pose);
    r.fused += f.fused ? 1 : 0;
  }
  return r;
}

void expect_gpu_tracks_as_the_cpu(sim::Profile profile) {
  const test::Recording rec = test::record(profile, kDuration_s, kAllPoints);
  const ReplayRun cpu = replay(rec, Device::Cpu);
  const ReplayRun gpu = replay(rec, Device::Cuda);
  ASSERT_EQ(cpu.poses.size(), gpu.poses.size());
  double worst_t = 0.0, worst_r = 0.0;
  for (std::size_t i = 0; i < cpu.poses.size(); ++i) {
    const SE3 d = cpu.poses[i].inverse() * gpu.poses[i];
    worst_t = std::max(worst_t, d.translation().norm());
    worst_r = std::max(worst_r, d.angle_rad() * 180.0 / M_PI);
  }
  // the runs' poses are already relative to their first scan
  const double cpu_error = test::final_position_error_m(rec, SE3(), cpu.poses.back());
  const double gpu_error = test::final_position_error_m(rec, SE3(), gpu.poses.back());
  std::printf(
      "%s LIO, %zu scans: GPU vs CPU poses within %.2e m, %.2e deg; final position error CPU %.3f m, "
      "GPU %.3f m; fused CPU %zu, GPU %zu\n",
      sim::profile_name(profile).c_str(), cpu.poses.size(), worst_t, worst_r, cpu_error, gpu_error, cpu.fused,
      gpu.fused);
  EXPECT_EQ(cpu.fused, gpu.fused);
  EXPECT_LT(worst_t, kMaxPoseDiff_m);
  EXPECT_LT(worst_r, kMaxPoseDiff_deg);
  EXPECT_LT(gpu_error, cpu_error + kMaxExtraFinalError_m);
}

}  // namespace

TEST(CudaOdometry, UrbanLioOnTheGpuTracksAsOnTheCpu) {
  FARLIO_REQUIRE_GPU();
  expect_gpu_tracks_as_the_cpu(sim::Profile::Urban);
}

TEST(CudaOdometry, RacetrackLioOnTheGpuTracksAsOnTheCpu) {
  FARLIO_REQUIRE_GPU();
  expect_gpu_tracks_as_the_cpu(sim::Profile::Racetrack);
}
