// The fusion's clock and the IMU's units (docs/hardening.md, "Configuration and clocks"): spans
// of IMU and scan stamps that do not overlap are named with the unit that would make them; the
// IMU clock jumping far ahead or back resets the fusion instead of dead-reckoning across the
// jump; out-of-order samples never repeat an output stamp; the replay sorts unsorted IMU and runs
// scans before the IMU LiDAR-only; a gyro in deg/s is scaled, a stuck gyro and a silent
// accelerometer end the fusion, each with a warning.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "farlio/core/clock_check.hpp"
#include "farlio/core/error.hpp"
#include "farlio/core/time.hpp"
#include "farlio/fusion/gyro_unit_detector.hpp"
#include "farlio/pipeline/odometry.hpp"
#include "farlio/pipeline/online_odometry.hpp"
#include "sim_recording.hpp"

using namespace farlio;
using namespace farlio::pipeline;
using test::deterministic_config;
using test::Recording;

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr std::int64_t kNsPerUs = 1000;
constexpr std::size_t kKeepEvery = 4;  // every 4th point keeps sanitizer runs short

const Recording& urban() {  // 15 scans, a straight road
  static const Recording r = test::record(sim::Profile::Urban, 1.5, kKeepEvery);
  return r;
}

const Recording& handheld() {  // 50 scans through rooms: the sensor turns from 2.2 s on
  static const Recording r = test::record(sim::Profile::Handheld, 5.0, kKeepEvery);
  return r;
}

/// The same with every point: the registration must follow the turn from a deg/s gyro's guess (57
/// times the turn) until the unit is decided. With a quarter of the points and the finer voxel of
/// map.auto_min_voxels the registrations in the turn fail and the unit is never decided; with the
/// range rule's voxel (map.auto_min_voxels 0) it is (docs/odometry.md, step 0).
const Recording& handheld_every_point() {
  static const Recording r = test::record(sim::Profile::Handheld, 5.0, 1);
  return r;
}

/// The Livox Avia cut 8 s into the handheld walk, 4 s: the walker stops facing a wall (every scan
/// degenerate) and looks around.
const Recording& avia_facing_a_wall() {
  static const Recording r = test::record(sim::Profile::Handheld, 4.0, 1, 8.0, sim::LidarModel::Avia);
  return r;
}

/// The same samples with the gyro in deg/s.
std::vector<ImuSample> in_degrees_per_second(std::vector<ImuSample> imu) {
  for (auto& s : imu) s.gyro_rad_s *= kDegPerRad;
  return imu;
}

bool contains(const std::vector<std::string>& warnings, const std::string& fragment) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(fragment) != std::string::npos; });
}

std::string joined(const std::vector<std::string>& warnings) {
  std::string s;
  for (const auto& w : warnings) s += w + "\n";
  return s;
}

/// The replay of `rec` (zero latency) with its IMU replaced; frames, outputs and warnings.
struct ReplayRun {
  std::vector<OdometryFrame> frames;
  std::vector<OdometrySample> outputs;
  std::vector<std::string> warnings;
  bool inertial_at_end = false;
};

ReplayRun replay(const Recording& rec, std::vector<ImuSample> imu, const std::vector<Scan>* scans = nullptr,
                 const Config& config = deterministic_config()) {
  ReplayOptions zero;
  zero.latency = LatencyModel::Zero;
  Odometry odo(config, rec.T_imu_lidar, rec.gravity_m_s2, std::move(imu), zero);
  ReplayRun run;
  odo.on_odometry = [&](const OdometrySample& s) { run.outputs.push_back(s); };
  for (const Scan& s : scans ? *scans : rec.scans) run.frames.push_back(odo.process(s));
  odo.finish((scans ? *scans : rec.scans).back().end_stamp_ns);
  run.warnings = odo.take_warnings();
  run.inertial_at_end = odo.inertial();
  return run;
}

/// The largest rotation between outputs of `run` and `reference` at the same stamp (deg); `compared`
/// counts those stamps.
double max_rotation_difference_deg(const std::vector<OdometrySample>& run, const std::vector<OdometrySample>& reference,
                                   std::size_t* compared = nullptr) {
  double max_deg = 0.0;
  for (const OdometrySample& s : run) {
    const auto same = std::find_if(reference.begin(), reference.end(),
                                   [&](const OdometrySample& f) { return f.stamp_ns == s.stamp_ns; });
    if (same == reference.end()) continue;
    max_deg = std::max(max_deg, kDegPerRad * (same->body_pose.inverse() * s.body_pose).angle_rad());
    if (compared) ++*compared;
  }
  return max_deg;
}

double final_position_error_m(const Recording& rec, const ReplayRun& run) {
  return test::final_position_error_m(rec, run.frames.front().body_pose, run.frames.back().body_pose);
}

/// Pushes the IMU and the scans of `rec` to an online odometry in stamp order, scan by scan
/// (each scan after the IMU up to its end), applying `imu_at(i)` to choose the sample pushed i-th.
struct OnlineRun {
  std::vector<OdometrySample> outputs;
  std::vector<OdometryFrame> frames;
  std::vector<std::string> warnings;
  bool inertial = false;
};

template <typename Push>
OnlineRun online_run(const Recording& rec, Push&& push) {
  OnlineRun run;
  std::mutex m;
  OnlineOdometry online(
      deterministic_config(), rec.T_imu_lidar, rec.gravity_m_s2,
      [&](const OdometrySample& s) { run.outputs.push_back(s); },
      [&](const OdometryFrame& f) {
        std::lock_guard lock(m);
        run.frames.push_back(f);
      });
  push(online);
  online.stop();
  run.warnings = online.take_warnings();
  run.inertial = online.inertial();
  return run;
}

void push_scan(OnlineOdometry& online, const Scan& scan) {
  online.add_scan(scan);
  online.wait_idle();
}

void expect_increasing(const std::vector<OdometrySample>& outputs) {
  for (std::size_t i = 1; i < outputs.size(); ++i) {
    ASSERT_GT(outputs[i].stamp_ns, outputs[i - 1].stamp_ns) << "output " << i << " repeats or goes back";
  }
}

}  // namespace

// ---- the clock check ---------------------------------------------------------------------------

TEST(ClockCheck, SpansOfOneClockPass) {
  const ClockCheck c = check_clocks({1'700'000'000'000'000'000, 1'700'000'010'000'000'000},
                                    {1'700'000'000'100'000'000, 1'700'000'010'000'000'000}, 1.0);
  EXPECT_EQ(c.error, "");
  EXPECT_TRUE(c.warnings.empty()) << joined(c.warnings);
}

TEST(ClockCheck, StampsInAnotherUnitAreNamed) {
  const StampSpan imu_ns{1'700'000'000'000'000'000, 1'700'000'010'000'000'000};
  const StampSpan scans_us{1'700'000'000'100'000, 1'700'000'010'000'000};
  const ClockCheck scans = check_clocks(imu_ns, scans_us, 1.0);
  EXPECT_NE(scans.error.find("IMU stamps span [1700000000.000, 1700000010.000] s, scans span [1700000.000, "
                             "1700000.010] s: they do not overlap"),
            std::string::npos)
      << scans.error;
  EXPECT_NE(scans.error.find("scan stamps would overlap the IMU: are the scans"), std::string::npos) << scans.error;
  EXPECT_NE(scans.error.find("stamped in us?"), std::string::npos) << scans.error;

  const StampSpan imu_us{1'700'000'000'000'000, 1'700'000'010'000'000};
  const StampSpan scans_ns{1'700'000'000'100'000'000, 1'700'000'010'000'000'000};
  const ClockCheck imu = check_clocks(imu_us, scans_ns, 1.0);
  EXPECT_NE(imu.error.find("the IMU stamps would overlap the scans: is imu.csv (or the IMU topic) stamped in us?"),
            std::string::npos)
      << imu.error;
}

TEST(ClockCheck, AnOffsetOfSecondsIsAWarning) {
  const StampSpan scans{1'700'000'000'100'000'000, 1'700'000'003'000'000'000};
  const ClockCheck late = check_clocks({1'700'000'002'000'000'000, 1'700'000'005'000'000'000}, scans, 1.0);
  EXPECT_EQ(late.error, "");
  ASSERT_EQ(late.warnings.size(), 1u);
  EXPECT_NE(late.warnings[0].find("the IMU starts 1.900 s after the first scan"), std::string::npos)
      << late.warnings[0];
  const ClockCheck early = check_clocks({1'699'999'998'000'000'000, 1'700'000'001'000'000'000}, scans, 1.0);
  ASSERT_EQ(early.warnings.size(), 1u);
  EXPECT_NE(early.warnings[0].find("the IMU ends 2.000 s before the last scan"), std::string::npos)
      << early.warnings[0];
  EXPECT_NE(check_clocks({1'700'000'010'000'000'000, 1'700'000'020'000'000'000}, scans, 1.0).error, "");
}

// ---- the gyro's unit ---------------------------------------------------------------------------

namespace {

/// Feeds `seconds` of a gyro turning at `rate_rad_s` about z (reported times `unit`, plus a
/// bias) at 100 Hz and the LiDAR's rotation every 0.1 s.
void turn(fusion::GyroUnitDetector& d, std::int64_t& t_ns, double seconds, double rate_rad_s, double unit,
          double bias_rad_s = 0.0) {
  constexpr std::int64_t kImuStepNs = 10'000'000, kScanNs = 100'000'000;
  const std::int64_t end = t_ns + seconds_to_ns(seconds);
  while (t_ns < end) {
    const std::int64_t scan_start = t_ns;
    for (; t_ns < scan_start + kScanNs; t_ns += kImuStepNs) {
      ImuSample s;
      s.stamp_ns = t_ns + kImuStepNs;
      s.gyro_rad_s = Eigen::Vector3d(0.0, 0.0, rate_rad_s * unit + bias_rad_s);
      s.accel_m_s2 = Eigen::Vector3d(0.0, 0.0, 9.81);
      d.add_imu(s);
    }
    d.add_lidar_rotation(scan_start, t_ns, Eigen::Vector3d(0.0, 0.0, rate_rad_s * ns_to_seconds(kScanNs)));
  }
}

}  // namespace

TEST(GyroUnit, DegreesPerSecondAreFoundAndScaled) {
  fusion::GyroUnitDetector d(true, 0.3, 0.05);
  std::int64_t t = 0;
  turn(d, t, 0.4, 0.5, kDegPerRad);  // the LiDAR turned 0.15 rad (the first interval is not covered)
  EXPECT_FALSE(d.decided());
  EXPECT_TRUE(d.turning(0, t));  // meanwhile the fusion's guess is not used
  turn(d, t, 0.4, 0.5, kDegPerRad);
  ASSERT_EQ(d.unit(), fusion::GyroUnit::kDegreesPerSecond);
  EXPECT_NEAR(d.scale(), 1.0 / kDegPerRad, 1e-12);
  EXPECT_NE(d.message().find("the gyro reports in deg/s"), std::string::npos) << d.message();
  EXPECT_FALSE(d.turning(0, t));  // decided: the guess is used again
}

/// Feeds `seconds` of a drive that does not turn: small rotations about all axes (lane keeping,
/// grade, sway: rates of sway_rad_s varying at about 0.3 Hz) reported times `unit` plus a bias and
/// white noise, at 100 Hz; the LiDAR's rotation every 0.1 s with lidar_noise_rad of noise.
/// Returns the seconds it took to decide (or `seconds` when it did not).
double drive_straight(fusion::GyroUnitDetector& d, double seconds, double sway_rad_s, double unit, double bias_rad_s,
                      double gyro_noise_rad_s, double lidar_noise_rad, unsigned seed) {
  constexpr std::int64_t kImuStepNs = 10'000'000, kScanNs = 100'000'000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto rate = [&](double t) {
    return Eigen::Vector3d(sway_rad_s * std::sin(1.9 * t), 0.7 * sway_rad_s * std::sin(2.3 * t + 1.0),
                           sway_rad_s * std::sin(1.3 * t + 2.0));
  };
  std::int64_t t_ns = 0;
  while (t_ns < seconds_to_ns(seconds)) {
    const std::int64_t scan_start = t_ns;
    Eigen::Vector3d truth = Eigen::Vector3d::Zero();
    for (; t_ns < scan_start + kScanNs; t_ns += kImuStepNs) {
      ImuSample s;
      s.stamp_ns = t_ns + kImuStepNs;
      const Eigen::Vector3d w = rate(ns_to_seconds(s.stamp_ns));
      truth += w * ns_to_seconds(kImuStepNs);
      s.gyro_rad_s = unit * (w + Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * gyro_noise_rad_s) +
                     Eigen::Vector3d::Constant(bias_rad_s);
      s.accel_m_s2 = Eigen::Vector3d(0.0, 0.0, 9.81);
      d.add_imu(s);
    }
    d.add_lidar_rotation(scan_start, t_ns,
                         truth + Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * lidar_noise_rad);
    if (d.decided()) return ns_to_seconds(t_ns);
  }
  return seconds;
}

TEST(GyroUnit, DegreesPerSecondAreFoundBeforeTheFirstTurn) {
  // a straight drive: the body sways by 0.01 rad/s, the LiDAR's rotations carry 2e-4 rad of
  // noise; deg/s and rad/s are both told apart within seconds, for several noise draws
  for (unsigned seed = 1; seed <= 5; ++seed) {
    fusion::GyroUnitDetector deg(true, 0.1, 0.05), rad(true, 0.1, 0.05);
    EXPECT_LT(drive_straight(deg, 30.0, 0.01, kDegPerRad, 0.5, 0.003, 2e-4, seed), 10.0) << seed;
    EXPECT_EQ(deg.unit(), fusion::GyroUnit::kDegreesPerSecond) << seed;
    EXPECT_NE(deg.message().find("the gyro reports in deg/s"), std::string::npos) << deg.message();
    EXPECT_LT(drive_straight(rad, 30.0, 0.01, 1.0, 0.01, 0.003, 2e-4, seed), 10.0) << seed;
    EXPECT_EQ(rad.unit(), fusion::GyroUnit::kRadPerSecond) << seed;
  }
}

TEST(GyroUnit, WithoutRotationTheNoiseTellsRadPerSecondAndNothingElse) {
  // no rotation at all: a MEMS gyro's noise (0.003 rad/s a sample) is rad/s; the same gyro in deg/s
  // (0.17 a sample) and a vibrating one in rad/s (0.05 a sample) decide nothing
  for (unsigned seed = 1; seed <= 5; ++seed) {
    fusion::GyroUnitDetector rad(true, 0.1, 0.05), deg(true, 0.1, 0.05), shaken(true, 0.1, 0.05);
    EXPECT_LT(drive_straight(rad, 30.0, 0.0, 1.0, 0.01, 0.003, 2e-4, seed), 2.0) << seed;
    EXPECT_EQ(rad.unit(), fusion::GyroUnit::kRadPerSecond) << seed;
    drive_straight(deg, 30.0, 0.0, kDegPerRad, 0.01, 0.003, 2e-4, seed);
    EXPECT_FALSE(deg.decided()) << seed;
    drive_straight(shaken, 30.0, 0.0, 1.0, 0.01, 0.05, 2e-4, seed);
    EXPECT_FALSE(shaken.decided()) << seed;
  }
}

TEST(GyroUnit, ABiasAtRestDoesNotLookLikeDegrees) {
  // 30 s at rest with a 0.05 rad/s bias (3 deg/s: a poor gyro), then a turn: rad/s
  fusion::GyroUnitDetector d(true, 0.3, 0.05);
  std::int64_t t = 0;
  turn(d, t, 30.0, 0.0, 1.0, 0.05);
  EXPECT_FALSE(d.decided());
  turn(d, t, 1.0, 0.5, 1.0, 0.05);
  EXPECT_EQ(d.unit(), fusion::GyroUnit::kRadPerSecond);
  EXPECT_EQ(d.scale(), 1.0);
  EXPECT_EQ(d.message(), "");
}

TEST(GyroUnit, AStuckGyroIsFound) {
  fusion::GyroUnitDetector d(true, 0.3, 0.05);
  std::int64_t t = 0;
  constexpr std::int64_t kScanNs = 100'000'000;
  for (int k = 0; k < 20 && !d.decided(); ++k) {
    for (int j = 1; j <= 10; ++j) {
      ImuSample s;
      s.stamp_ns = t + j * kScanNs / 10;
      s.gyro_rad_s = Eigen::Vector3d(0.001, 0.0, 0.0);  // never changes
      d.add_imu(s);
    }
    d.add_lidar_rotation(t, t + kScanNs, Eigen::Vector3d(0.0, 0.0, 0.05));  // the LiDAR turns 0.5 rad/s
    t += kScanNs;
  }
  EXPECT_EQ(d.unit(), fusion::GyroUnit::kStuck);
  EXPECT_NE(d.message().find("the gyro is stuck"), std::string::npos) << d.message();
}

TEST(GyroUnit, DisabledMeansRadPerSecond) {
  const fusion::GyroUnitDetector d(false, 0.3, 0.05);
  EXPECT_EQ(d.unit(), fusion::GyroUnit::kRadPerSecond);
  EXPECT_FALSE(d.turning(0, 1'000'000'000));
}

TEST(GyroUnit, ASilentAccelerometerIsNamed) {
  EXPECT_NE(fusion::silent_accelerometer(std::vector<Eigen::Vector3d>(50, Eigen::Vector3d::Zero()))
                .find("the accelerometer reads zero"),
            std::string::npos);
  EXPECT_EQ(fusion::silent_accelerometer(std::vector<Eigen::Vector3d>(50, Eigen::Vector3d(0, 0, 9.81))), "");
  EXPECT_EQ(fusion::silent_accelerometer(std::vector<Eigen::Vector3d>(50, Eigen::Vector3d(0, 0, 1.0))), "");  // in g
  EXPECT_EQ(fusion::silent_accelerometer({}), "");
}

// ---- the replay --------------------------------------------------------------------------------

TEST(ReplayClocks, UnsortedImuIsSortedWithAWarning) {
  const Recording& rec = urban();
  std::vector<ImuSample> shuffled = rec.imu;
  for (std::size_t i = 10; i + 1 < shuffled.size(); i += 7) std::swap(shuffled[i], shuffled[i + 1]);
  const ReplayRun sorted = replay(rec, rec.imu);
  const ReplayRun run = replay(rec, shuffled);
  EXPECT_TRUE(contains(run.warnings, "IMU samples are not in time order")) << joined(run.warnings);
  ASSERT_EQ(run.frames.size(), sorted.frames.size());
  for (std::size_t i = 0; i < run.frames.size(); ++i) {
    EXPECT_TRUE(run.frames[i].processed) << "scan " << i << ": " << run.frames[i].drop_reason;
    EXPECT_LT((run.frames[i].body_pose.translation() - sorted.frames[i].body_pose.translation()).norm(), 1e-9);
  }
}

TEST(ReplayClocks, ScansBeforeTheImuRunLidarOnlyThenTheImuIsUsed) {
  // the IMU's clock 0.5 s behind: the first five scans end before its first sample
  const Recording& rec = urban();
  std::vector<ImuSample> late = rec.imu;
  for (auto& s : late) s.stamp_ns += 500'000'000;
  const ReplayRun run = replay(rec, late);
  int fused = 0;
  for (const auto& f : run.frames) {
    EXPECT_TRUE(f.processed) << f.drop_reason;  // none dropped as "still busy"
    fused += f.fused ? 1 : 0;
  }
  EXPECT_FALSE(run.frames[2].fused);  // before the IMU: LiDAR-only
  EXPECT_GE(fused, 5);
  EXPECT_TRUE(run.inertial_at_end);
  EXPECT_GT(run.outputs.size(), 50u);
  expect_increasing(run.outputs);
}

TEST(ReplayClocks, ScansStampedInMicrosecondsRunLidarOnlyWithoutAHang) {
  // before: the filter initialised at the first scan and stepped 10 ms at a time across the
  // 1.7e9 s to the IMU's clock
  const Recording& rec = urban();
  std::vector<Scan> scans_us = rec.scans;
  for (auto& s : scans_us) {  // named in us (no per-point times: they would not fit the 100 us period)
    s.end_stamp_ns /= kNsPerUs;
    s.start_stamp_ns = s.end_stamp_ns;
    s.time_s.clear();
  }
  const ReplayRun run = replay(rec, rec.imu, &scans_us);
  for (const auto& f : run.frames) {
    EXPECT_TRUE(f.processed);
    EXPECT_FALSE(f.fused);
  }
  EXPECT_TRUE(run.outputs.empty());
}

TEST(ReplayClocks, AFirstScanAfterTheImuEndsIsAnError) {
  const Recording& rec = urban();
  std::vector<ImuSample> imu_us = rec.imu;
  for (auto& s : imu_us) s.stamp_ns /= kNsPerUs;
  Odometry odo(deterministic_config(), rec.T_imu_lidar, rec.gravity_m_s2, imu_us);
  try {
    (void)odo.process(rec.scans.front());
    FAIL() << "accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("they do not overlap"), std::string::npos) << msg;
    EXPECT_NE(msg.find("is imu.csv (or the IMU topic) stamped in us?"), std::string::npos) << msg;
  }
}

TEST(ReplayClocks, AGyroInDegreesPerSecondIsScaled) {
  const Recording& rec = handheld_every_point();
  const std::vector<ImuSample> deg = in_degrees_per_second(rec.imu);
  const ReplayRun normal = replay(rec, rec.imu);
  const ReplayRun run = replay(rec, deg);
  EXPECT_TRUE(contains(run.warnings, "the gyro reports in deg/s")) << joined(run.warnings);
  EXPECT_FALSE(contains(normal.warnings, "the gyro")) << joined(normal.warnings);
  EXPECT_TRUE(run.inertial_at_end);
  // the run ends as accurate as with the gyro in rad/s
  const double normal_m = final_position_error_m(rec, normal), deg_m = final_position_error_m(rec, run);
  EXPECT_LT(deg_m, 2.0 * normal_m + 0.02) << "rad/s: " << normal_m << " m";
}

// A narrow field of view facing a wall: the Livox Avia cut 8 s into the handheld walk, as the walker
// stops and looks around. Its scans are degenerate, so the unit is not judged on them; the gyro
// turns the fusion's guess of the look-around once a clear turn that the LiDAR found from its own
// guess agrees with it (the rad/s run ends 0.07 m from the truth). A deg/s gyro must not get there
// through the LiDAR's noise (0.012 against 0.0135 rad over a scan): a rule that took any agreement
// of 0.01 rad or more confirmed it, and it was never found (3.3 m off at the end of these 4 s, 128 m
// over 20 s).
TEST(ReplayClocks, AGyroInDegreesPerSecondFacingAWallIsFound) {
  const Recording& rec = avia_facing_a_wall();
  const std::vector<ImuSample> deg = in_degrees_per_second(rec.imu);
  const ReplayRun normal = replay(rec, rec.imu);
  const ReplayRun run = replay(rec, deg);
  EXPECT_TRUE(contains(run.warnings, "the gyro reports in deg/s")) << joined(run.warnings);
  EXPECT_FALSE(contains(normal.warnings, "the gyro reports")) << joined(normal.warnings);
  EXPECT_LT(final_position_error_m(rec, normal), 0.15);
}

// The kernel scale with the fusion's guess: capped at registration.fused_kernel_scale_m until the
// gyro's unit is decided against the LiDAR, at confirmed_kernel_scale_m after, never back.
TEST(ReplayClocks, TheFusionsGuessGetsTheTightKernelOnceTheGyroIsConfirmed) {
  const ReplayRun run = replay(handheld(), handheld().imu);
  const RegistrationConfig& reg = deterministic_config().registration;
  int confirmed = 0;
  bool seen_confirmed = false;
  for (const auto& f : run.frames) {
    if (!f.guess_from_fusion || !f.scan.registered) continue;
    const double loose = std::min(f.scan.sigma_m / 3.0, reg.fused_kernel_scale_m);
    const double tight = std::min(f.scan.sigma_m / 3.0, reg.confirmed_kernel_scale_m);
    ASSERT_TRUE(f.scan.kernel_scale_m == loose || f.scan.kernel_scale_m == tight) << f.scan.kernel_scale_m;
    if (tight < loose && f.scan.kernel_scale_m == tight) {
      ++confirmed;
      seen_confirmed = true;
    }
    if (seen_confirmed) EXPECT_EQ(f.scan.kernel_scale_m, tight);
  }
  EXPECT_GT(confirmed, 10);
}

TEST(ReplayClocks, AnUndecidedGyroUnitIsAWarning) {
  // the generator's urban drive goes straight for its first 12 s without any rotation: a gyro in
  // deg/s cannot be told from one in rad/s, and the run says so (before: nothing was said)
  static const Recording straight = test::record(sim::Profile::Urban, 12.0, kKeepEvery);
  const std::vector<ImuSample> deg = in_degrees_per_second(straight.imu);
  const ReplayRun run = replay(straight, deg);
  EXPECT_TRUE(contains(run.warnings, "the gyro's unit (rad/s or deg/s) is not decided after 10.000 s"))
      << joined(run.warnings);
  EXPECT_FALSE(contains(run.warnings, "the gyro reports in deg/s")) << joined(run.warnings);
}

// An IMU slower than the filter's step (10 Hz, KITTI raw's OXTS rate): each step reads the input
// interpolated between the samples around it, never the last sample held ahead of the next (that
// lags a turn by half a sample period: 0.9 deg of yaw through an urban corner and a run of rejected
// LiDAR results), so the 100 Hz output turns as with the full-rate IMU. The filter steps only as far
// as the newest sample while the next one is due: no output is emitted beyond it.
TEST(ReplayClocks, AnImuSlowerThanTheStepIsInterpolatedNotHeld) {
  // 100 Hz on the step grid; from 25 s into the urban drive the car turns into a cross street
  // (0.53 rad/s from 26.0 s to 27.3 s) after the filter started in motion
  static const Recording rec = test::record(sim::Profile::Urban, 3.0, kKeepEvery, 25.0);
  constexpr std::size_t kEvery = 10;  // 10 Hz
  const ReplayRun full = replay(rec, rec.imu);
  std::vector<ImuSample> slow;
  for (std::size_t i = 0; i < rec.imu.size(); i += kEvery) slow.push_back(rec.imu[i]);
  std::size_t compared = 0;
  // 0.08 deg; 0.21 deg with the input held
  EXPECT_LT(max_rotation_difference_deg(replay(rec, slow).outputs, full.outputs, &compared), 0.12);
  EXPECT_GT(compared, full.outputs.size() / 2);

  // the samples 40 ms after the scans' clock: outputs come as the IMU covers them
  std::vector<ImuSample> offset;
  for (std::size_t i = 4; i < rec.imu.size(); i += kEvery) offset.push_back(rec.imu[i]);
  // the gyro's rotation over a scan interval is compared with the LiDAR's once the IMU covers it,
  // so the gyro's unit is decided and the fusion's guess serves the corner: 0.37 deg from the
  // full-rate output (0.74 deg with the input held and the unit never decided)
  EXPECT_LT(max_rotation_difference_deg(replay(rec, offset).outputs, full.outputs), 0.45);
  ReplayOptions zero;
  zero.latency = LatencyModel::Zero;
  Odometry odo(deterministic_config(), rec.T_imu_lidar, rec.gravity_m_s2, offset, zero);
  std::vector<std::int64_t> emitted;
  odo.on_odometry = [&](const OdometrySample& s) { emitted.push_back(s.stamp_ns); };
  for (const Scan& scan : rec.scans) {
    emitted.clear();
    odo.process(scan);
    const auto newest = std::find_if(offset.rbegin(), offset.rend(),
                                     [&](const ImuSample& m) { return m.stamp_ns <= scan.end_stamp_ns; });
    ASSERT_NE(newest, offset.rend());
    for (const std::int64_t stamp : emitted) EXPECT_LE(stamp, newest->stamp_ns) << "scan ending " << scan.end_stamp_ns;
  }
}

// An IMU that stops: a result within fusion.imu_gate.max_bridged_gap_s of the newest sample waits
// for the IMU to cover it; one further on is not fused, and its frame says why.
TEST(ReplayClocks, AResultFarBeyondTheNewestImuSampleIsNotFused) {
  const Recording& rec = urban();  // 15 scans over 1.5 s
  std::vector<ImuSample> first_part;
  for (const ImuSample& s : rec.imu)
    if (s.stamp_ns <= rec.imu.front().stamp_ns + 300'000'000) first_part.push_back(s);
  const ReplayRun run = replay(rec, first_part);
  int beyond = 0;
  for (const OdometryFrame& f : run.frames) {
    const double after_s = ns_to_seconds(f.scan.stamp_ns) - ns_to_seconds(first_part.back().stamp_ns);
    if (after_s <= deterministic_config().fusion.imu_gate.max_bridged_gap_s) continue;
    ++beyond;
    EXPECT_FALSE(f.fused);
    EXPECT_NE(f.drop_reason.find("after the newest IMU sample"), std::string::npos) << f.drop_reason;
  }
  EXPECT_GE(beyond, 2);
  for (const auto& f : run.frames) EXPECT_TRUE(f.body_pose.translation().allFinite());
}

TEST(ReplayClocks, AStuckGyroEndsTheFusion) {
  const Recording& rec = handheld();
  std::vector<ImuSample> stuck = rec.imu;
  for (auto& s : stuck) s.gyro_rad_s = Eigen::Vector3d(0.002, -0.001, 0.0);
  const ReplayRun run = replay(rec, stuck);
  EXPECT_TRUE(contains(run.warnings, "the gyro is stuck")) << joined(run.warnings);
  EXPECT_FALSE(run.inertial_at_end);
  // a guess from a gyro not confirmed against the LiDAR never gets the tight kernel: the scans
  // must still be able to show the turn the gyro misses
  const RegistrationConfig& reg = deterministic_config().registration;
  for (const auto& f : run.frames) {
    if (f.guess_from_fusion && f.scan.registered)
      EXPECT_DOUBLE_EQ(f.scan.kernel_scale_m, std::min(f.scan.sigma_m / 3.0, reg.fused_kernel_scale_m));
  }
  for (const auto& f : run.frames) EXPECT_TRUE(f.body_pose.translation().allFinite());
}

TEST(ReplayClocks, ASilentAccelerometerMeansLidarOnly) {
  const Recording& rec = urban();
  std::vector<ImuSample> silent = rec.imu;
  for (auto& s : silent) s.accel_m_s2.setZero();
  const ReplayRun run = replay(rec, silent);
  EXPECT_TRUE(contains(run.warnings, "the accelerometer reads zero")) << joined(run.warnings);
  EXPECT_FALSE(run.inertial_at_end);
  EXPECT_TRUE(run.outputs.empty());
}

TEST(ReplayClocks, BadGravityAndLatenciesAreErrorsNamingThem) {
  const Recording& rec = urban();
  for (const double g : {-9.81, 0.0, 1.0}) {
    try {
      Odometry odo(Config{}, rec.T_imu_lidar, g, rec.imu);
      ADD_FAILURE() << "gravity " << g << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("gravity_m_s2: must be the magnitude of gravity"), std::string::npos)
          << e.what();
    }
  }
  ReplayOptions negative;
  negative.added_delay_s = -5.0;
  try {
    Odometry odo(Config{}, rec.T_imu_lidar, rec.gravity_m_s2, rec.imu, negative);
    ADD_FAILURE() << "a negative delay was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ReplayOptions.added_delay_s must be in [0, 60] s"), std::string::npos)
        << e.what();
  }
}

// ---- the online odometry -----------------------------------------------------------------------

namespace {

/// Pushes the recording in stamp order: the IMU up to each scan's end, then the scan;
/// `sample(i)` is what is pushed for IMU sample i (it may push more).
template <typename Sample>
void push_in_order(OnlineOdometry& online, const Recording& rec, Sample&& sample) {
  std::size_t next = 0;
  for (const Scan& scan : rec.scans) {
    while (next < rec.imu.size() && rec.imu[next].stamp_ns <= scan.end_stamp_ns) sample(online, next++);
    push_scan(online, scan);
  }
  while (next < rec.imu.size()) sample(online, next++);
}

}  // namespace

// The online odometry (the ROS 2 node's) finds a deg/s gyro facing a wall as the replay does
// (ReplayClocks.AGyroInDegreesPerSecondFacingAWallIsFound): both register through
// register_from_prior, which tells the gyro's unit check which guesses the gyro turned.
TEST(OnlineClocks, AGyroInDegreesPerSecondFacingAWallIsFound) {
  const Recording& rec = avia_facing_a_wall();
  const std::vector<ImuSample> deg = in_degrees_per_second(rec.imu);
  const OnlineRun run = online_run(rec, [&](OnlineOdometry& online) {
    push_in_order(online, rec, [&](OnlineOdometry& o, std::size_t i) { o.add_imu(deg[i]); });
  });
  EXPECT_TRUE(contains(run.warnings, "the gyro reports in deg/s")) << joined(run.warnings);
}

TEST(OnlineClocks, OneFarFutureImuStampCostsOneSample) {
  // a single sample stamped 10,000 s ahead: that one sample is dropped (not the fusion reset twice,
  // ahead and back, nor every later sample dropped) and the run is the run without it
  const Recording& rec = urban();
  constexpr std::int64_t kJumpNs = 10'000LL * kNsPerSecond;
  const std::size_t bad = rec.imu.size() / 2;
  const auto push_with_future = [&](bool with_future) {
    return online_run(rec, [&](OnlineOdometry& online) {
      push_in_order(online, rec, [&](OnlineOdometry& o, std::size_t i) {
        o.add_imu(rec.imu[i]);
        if (i != bad || !with_future) return;
        ImuSample future = rec.imu[i];
        future.stamp_ns += kJumpNs;
        o.add_imu(future);
      });
    });
  };
  const OnlineRun run = push_with_future(true), clean = push_with_future(false);
  EXPECT_TRUE(contains(run.warnings, "jumps by 10000.000 s from the samples around it: dropped"))
      << joined(run.warnings);
  EXPECT_FALSE(contains(run.warnings, "reset")) << joined(run.warnings);
  expect_increasing(run.outputs);
  ASSERT_EQ(run.outputs.size(), clean.outputs.size());
  for (std::size_t i = 0; i < run.outputs.size(); ++i) {
    EXPECT_EQ(run.outputs[i].stamp_ns, clean.outputs[i].stamp_ns);
    EXPECT_LT((run.outputs[i].body_pose.translation() - clean.outputs[i].body_pose.translation()).norm(), 1e-9);
  }
}

TEST(OnlineClocks, AnImuClockThatJumpsIsAResetNotADeadReckoning) {
  // every sample from the middle on 10,000 s ahead: the clock jumped; no dead reckoning across
  // it, nothing emitted twice, and the scans (still on the old clock) are not fused after it
  const Recording& rec = urban();
  constexpr std::int64_t kJumpNs = 10'000LL * kNsPerSecond;
  const std::size_t from = rec.imu.size() / 2;
  const OnlineRun run = online_run(rec, [&](OnlineOdometry& online) {
    push_in_order(online, rec, [&](OnlineOdometry& o, std::size_t i) {
      ImuSample s = rec.imu[i];
      if (i >= from) s.stamp_ns += kJumpNs;
      o.add_imu(s);
    });
  });
  EXPECT_TRUE(contains(run.warnings, "jumps by 10000.010 s")) << joined(run.warnings);
  EXPECT_TRUE(contains(run.warnings, "the fusion is reset")) << joined(run.warnings);
  expect_increasing(run.outputs);
  EXPECT_LT(run.outputs.size(), rec.imu.size());
  for (const auto& s : run.outputs) EXPECT_LT(s.body_pose.translation().norm(), 100.0);
}

TEST(OnlineClocks, AFarFutureStampBeforeInitialisationDoesNotBlock) {
  // before: +1e17 ns before the first scan blocked add_imu for 42 s, then dropped every sample
  const Recording& rec = urban();
  const OnlineRun run = online_run(rec, [&](OnlineOdometry& online) {
    push_in_order(online, rec, [&](OnlineOdometry& o, std::size_t i) {
      o.add_imu(rec.imu[i]);
      if (i != 3) return;
      ImuSample future = rec.imu[i];
      future.stamp_ns += 100'000'000'000'000'000;
      o.add_imu(future);
    });
  });
  EXPECT_TRUE(contains(run.warnings, "from the samples around it: dropped")) << joined(run.warnings);
  EXPECT_TRUE(run.inertial);
  EXPECT_GT(run.outputs.size(), 50u);
  expect_increasing(run.outputs);
}

TEST(OnlineClocks, OutOfOrderImuNeverRepeatsAnOutputStamp) {
  // before: blocks of samples pushed newest first emitted one stamp four times
  const Recording& rec = urban();
  constexpr std::size_t kBlock = 7;
  const OnlineRun run = online_run(rec, [&](OnlineOdometry& online) {
    std::size_t next = 0;
    for (const Scan& scan : rec.scans) {
      while (next < rec.imu.size() && rec.imu[next].stamp_ns <= scan.end_stamp_ns) {
        const std::size_t end = std::min(next + kBlock, rec.imu.size());
        for (std::size_t i = end; i > next; --i) online.add_imu(rec.imu[i - 1]);
        next = end;
      }
      push_scan(online, scan);
    }
  });
  ASSERT_GT(run.outputs.size(), 10u);
  expect_increasing(run.outputs);
}

TEST(OnlineClocks, AScanBeforeTheFirstImuSampleDoesNotMakeTheRunLidarOnly) {
  // before: the first scan fixed the mode; without IMU yet the whole run was LiDAR-only
  const Recording& rec = urban();
  const OnlineRun run = online_run(rec, [&](OnlineOdometry& online) {
    push_scan(online, rec.scans.front());  // no IMU sample yet
    std::size_t next = 0;
    for (std::size_t k = 1; k < rec.scans.size(); ++k) {
      while (next < rec.imu.size() && rec.imu[next].stamp_ns <= rec.scans[k].end_stamp_ns) {
        online.add_imu(rec.imu[next++]);
      }
      push_scan(online, rec.scans[k]);
    }
  });
  EXPECT_TRUE(run.inertial);
  ASSERT_EQ(run.frames.size(), rec.scans.size());
  EXPECT_FALSE(run.frames.front().fused);
  EXPECT_NE(run.frames.front().drop_reason.find("no IMU sample yet"), std::string::npos)
      << run.frames.front().drop_reason;
  EXPECT_TRUE(contains(run.warnings, "came before the first IMU sample")) << joined(run.warnings);
  EXPECT_TRUE(run.frames.back().fused);
  EXPECT_GT(run.outputs.size(), 50u);
  expect_increasing(run.outputs);
}

TEST(OnlineClocks, AResultFarBehindTheImuClockDoesNotInitialiseTheFilter) {
  // the IMU 5 s ahead of the scans: the filter would step 500 times (1.7e11 for clocks in
  // different units) from the scan to the IMU's clock
  const Recording& rec = urban();
  const OnlineRun run = online_run(rec, [&](OnlineOdometry& online) {
    for (const auto& s : rec.imu) {
      ImuSample ahead = s;
      ahead.stamp_ns += 5 * kNsPerSecond;
      online.add_imu(ahead);
    }
    push_scan(online, rec.scans[0]);
    push_scan(online, rec.scans[1]);
  });
  ASSERT_EQ(run.frames.size(), 2u);
  EXPECT_FALSE(run.frames[1].fused);
  EXPECT_NE(run.frames[1].drop_reason.find("beyond fusion.imu_gate.max_bridged_gap_s"), std::string::npos)
      << run.frames[1].drop_reason;
  EXPECT_TRUE(run.outputs.empty() || run.outputs.size() < 10u);
}
