// The threaded online odometry against the deterministic replay: pushed in lockstep from two
// threads it must give the replay's trajectory (zero latency), and pushed in real time it must
// keep its outputs consistent (every scan reported once, a regular 10 ms odometry).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_set>

#include "farlio/map/voxel_key.hpp"
#include "farlio/pipeline/odometry.hpp"
#include "farlio/pipeline/online_odometry.hpp"
#include "sim_recording.hpp"

using namespace farlio;
using namespace farlio::pipeline;

namespace {

using test::deterministic_config;
using test::Recording;

constexpr double kSeconds = 1.5;       // 15 scans: enough for the LIO to run, short under sanitizers
constexpr std::size_t kKeepEvery = 4;  // every 4th point (~30k per scan) keeps sanitizer runs short

const Recording& recording() {
  static const Recording r = test::record(sim::Profile::Urban, kSeconds, kKeepEvery);
  return r;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;  // frames take seconds: real-time pacing cannot keep up
#else
constexpr bool kSanitized = false;
#endif

}  // namespace

TEST(OnlineOdometry, LockstepFromTwoThreadsEqualsTheReplay) {
  const Recording& rec = recording();
  ASSERT_GE(rec.scans.size(), 12u);
  const Config config = deterministic_config();

  ReplayOptions zero;
  zero.latency = LatencyModel::Zero;
  Odometry replay(config, rec.T_imu_lidar, rec.gravity_m_s2, rec.imu, zero);
  std::vector<OdometrySample> expected;
  replay.on_odometry = [&](const OdometrySample& s) { expected.push_back(s); };
  std::vector<SE3> expected_scans;
  for (const auto& s : rec.scans) expected_scans.push_back(replay.process(s).body_pose);
  replay.finish(rec.imu.back().stamp_ns);

  std::vector<OdometrySample> got;
  std::vector<OdometryFrame> frames;
  std::mutex frames_mutex;
  OnlineOdometry online(
      config, rec.T_imu_lidar, rec.gravity_m_s2, [&](const OdometrySample& s) { got.push_back(s); },
      [&](const OdometryFrame& f) {
        std::lock_guard lock(frames_mutex);
        frames.push_back(f);
      });
  // IMU from one thread, scans from another: the IMU thread pushes everything up to a scan's
  // end, then the scan thread pushes that scan and waits until it is fused.
  std::mutex m;
  std::condition_variable cv;
  std::size_t imu_ready_for = 0;  // scans whose IMU has been pushed
  std::size_t scans_done = 0;
  std::thread imu_thread([&] {
    std::size_t next = 0;
    for (std::size_t i = 0; i <= rec.scans.size(); ++i) {
      const std::int64_t until = i < rec.scans.size() ? rec.scans[i].end_stamp_ns : rec.imu.back().stamp_ns;
      while (next < rec.imu.size() && rec.imu[next].stamp_ns <= until) online.add_imu(rec.imu[next++]);
      std::unique_lock lock(m);
      imu_ready_for = i + 1;
      cv.notify_all();
      cv.wait(lock, [&] { return scans_done >= std::min(i + 1, rec.scans.size()); });
    }
  });
  std::thread scan_thread([&] {
    for (std::size_t i = 0; i < rec.scans.size(); ++i) {
      {
        std::unique_lock lock(m);
        cv.wait(lock, [&] { return imu_ready_for > i; });
      }
      EXPECT_TRUE(online.add_scan(rec.scans[i]));
      online.wait_idle();
      std::lock_guard lock(m);
      scans_done = i + 1;
      cv.notify_all();
    }
  });
  imu_thread.join();
  scan_thread.join();
  online.stop();

  EXPECT_TRUE(online.inertial());
  ASSERT_EQ(frames.size(), rec.scans.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_TRUE(frames[i].processed);
    EXPECT_LT((frames[i].body_pose.translation() - expected_scans[i].translation()).norm(), 1e-6) << "scan " << i;
    // on the odometry's clock (the newest IMU stamp): the scan's IMU was pushed before the scan
    EXPECT_GT(frames[i].started_ns, rec.scans[i].start_stamp_ns) << "scan " << i;
    EXPECT_LE(frames[i].started_ns, rec.scans[i].end_stamp_ns) << "scan " << i;
    EXPECT_GE(frames[i].available_ns, frames[i].started_ns) << "scan " << i;
  }
  ASSERT_GT(expected.size(), 100u);  // 100 Hz over ~1.5 s
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].stamp_ns, expected[i].stamp_ns);
    EXPECT_LT((got[i].body_pose.translation() - expected[i].body_pose.translation()).norm(), 1e-6) << i;
  }
}

TEST(OnlineOdometry, StartedWhileTheCarDrivesItInitialisesInMotion) {
  // the online odometry started 10 s into the urban drive (12.7 m/s): no standstill, the filter
  // starts from the first 0.5 s of scans, and the run tracks the truth
  static const Recording rec = test::record(sim::Profile::Urban, 3.0, kKeepEvery, 10.0);
  std::vector<OdometrySample> outputs;
  std::vector<OdometryFrame> frames;
  OnlineOdometry online(
      deterministic_config(), rec.T_imu_lidar, rec.gravity_m_s2, [&](const OdometrySample& s) { outputs.push_back(s); },
      [&](const OdometryFrame& f) { frames.push_back(f); });
  std::size_t next = 0;
  for (const Scan& scan : rec.scans) {
    while (next < rec.imu.size() && rec.imu[next].stamp_ns <= scan.end_stamp_ns) online.add_imu(rec.imu[next++]);
    online.add_scan(scan);
    online.wait_idle();
  }
  online.stop();
  const auto stats = online.fusion_stats();
  ASSERT_TRUE(stats.has_value());
  EXPECT_EQ(stats->initialization.mode, "in motion");
  EXPECT_LE(ns_to_seconds(stats->initialization.stamp_ns - rec.scans.front().end_stamp_ns), 1.0);
  // the speed found against the truth's (central difference of the true scan-end positions)
  const auto k = static_cast<std::size_t>(
      std::find_if(rec.scans.begin(), rec.scans.end(),
                   [&](const Scan& s) { return s.end_stamp_ns == stats->initialization.stamp_ns; }) -
      rec.scans.begin());
  ASSERT_TRUE(k > 0 && k + 1 < rec.scans.size());
  const double true_speed_m_s =
      (rec.body_at_scan_end[k + 1].translation() - rec.body_at_scan_end[k - 1].translation()).norm() /
      ns_to_seconds(rec.scans[k + 1].end_stamp_ns - rec.scans[k - 1].end_stamp_ns);
  EXPECT_NEAR(stats->initialization.speed_m_s, true_speed_m_s, 0.2);
  EXPECT_EQ(stats->reinitializations, 0);
  ASSERT_EQ(frames.size(), rec.scans.size());
  ASSERT_GT(outputs.size(), 200u);  // 100 Hz from within 1 s of the first scan
  EXPECT_LT(test::final_position_error_m(rec, frames.front().body_pose, frames.back().body_pose), 0.1);
}

TEST(OnlineOdometry, RealTimeThreadsKeepTheOutputsConsistent) {
  const Recording& rec = recording();
  Config config;
  config.num_threads = test::kPipelineThreads;
  std::vector<OdometrySample> samples;
  std::atomic<int> processed{0}, dropped{0};
  OnlineOdometry online(
      config, rec.T_imu_lidar, rec.gravity_m_s2, [&](const OdometrySample& s) { samples.push_back(s); },
      [&](const OdometryFrame& f) { (f.processed ? processed : dropped)++; });
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const std::int64_t stamp0 = rec.imu.front().stamp_ns;
  auto wait_for_stamp = [&](std::int64_t stamp) {
    std::this_thread::sleep_until(t0 + std::chrono::nanoseconds(stamp - stamp0));
  };
  std::thread imu_thread([&] {
    for (const auto& s : rec.imu) {
      wait_for_stamp(s.stamp_ns);
      online.add_imu(s);
    }
  });
  std::thread scan_thread([&] {
    for (const auto& s : rec.scans) {
      wait_for_stamp(s.end_stamp_ns);
      online.add_scan(s);
    }
  });
  imu_thread.join();
  scan_thread.join();
  online.stop();
  // every scan is reported exactly once; the first is always processed (the worker is idle)
  EXPECT_EQ(processed + dropped, static_cast<int>(rec.scans.size()));
  EXPECT_GE(processed.load(), 1);
  // the odometry runs on the 10 ms grid without gaps or repeats (under a sanitizer the first
  // frame may finish after the last IMU sample, so that nothing is emitted)
  if (!kSanitized) {
    ASSERT_GT(samples.size(), 10u);
  }
  for (std::size_t i = 1; i < samples.size(); ++i) EXPECT_EQ(samples[i].stamp_ns - samples[i - 1].stamp_ns, 10'000'000);
  for (const auto& s : samples) EXPECT_TRUE(s.body_pose.translation().allFinite());
}

TEST(OnlineOdometry, RegisteredPointsAreTheScanInsertedIntoTheMap) {
  // LiDAR-only, scan after scan: every processed frame carries its kept points in the world
  // frame, and each of the last frame's points falls into a voxel of the submap snapshot (it was
  // just inserted there; nothing is removed near the sensor).
  const Recording& rec = recording();
  Config config = deterministic_config();
  config.map.auto_voxel_size = false;  // the voxel size the test maps points with
  constexpr std::size_t kScans = 4;
  std::vector<OdometryFrame> frames;
  std::mutex frames_mutex;
  OnlineOdometry online(
      config, rec.T_imu_lidar, rec.gravity_m_s2, {},
      [&](const OdometryFrame& f) {
        std::lock_guard lock(frames_mutex);
        frames.push_back(f);
      },
      /*keep_registered_points=*/true);
  EXPECT_TRUE(online.map_snapshot().voxel_keys.empty());  // before the first scan
  for (std::size_t i = 0; i < kScans; ++i) {
    ASSERT_TRUE(online.add_scan(rec.scans[i]));
    online.wait_idle();
  }
  const map::MapSnapshot snapshot = online.map_snapshot();
  online.stop();
  ASSERT_EQ(frames.size(), kScans);
  for (const auto& f : frames) {
    EXPECT_EQ(f.registered_points.size(), f.scan.kept_points);
    EXPECT_GT(f.registered_points.size(), 1000u);
  }
  std::unordered_set<std::uint64_t> occupied;
  for (std::size_t v = 0; v < snapshot.voxel_keys.size(); ++v) {
    if (snapshot.voxel_counts[v] > 0) occupied.insert(snapshot.voxel_keys[v]);
  }
  const auto inv_voxel = static_cast<float>(1.0 / config.map.voxel_size_m);
  std::size_t outside = 0;
  for (const auto& p : frames.back().registered_points) {
    outside += occupied.count(map::pack_key(map::voxel_of(p, inv_voxel))) == 0 ? 1 : 0;
  }
  EXPECT_EQ(outside, 0u);
}

TEST(Replay, ResultsArrivingAfterTheLastImuSampleAreNoImuGap) {
  // With a large added delay the last results arrive after the recording's IMU ends; that is the
  // end of the data, not a gap to warn about, and those results are still fused.
  const Recording& rec = recording();
  ReplayOptions late;
  late.latency = LatencyModel::Fixed;
  late.added_delay_s = 0.3;
  Odometry replay(deterministic_config(), rec.T_imu_lidar, rec.gravity_m_s2, rec.imu, late);
  int fused = 0;
  std::int64_t last_output_ns = 0;
  replay.on_odometry = [&](const OdometrySample& s) { last_output_ns = s.stamp_ns; };
  for (const auto& s : rec.scans) fused += replay.process(s).fused ? 1 : 0;
  replay.finish(rec.scans.back().end_stamp_ns + 1'000'000'000);
  ASSERT_TRUE(replay.fusion_stats().has_value());
  EXPECT_EQ(replay.fusion_stats()->imu_gaps, 0);
  EXPECT_GE(fused, 3);
  EXPECT_LE(last_output_ns, rec.imu.back().stamp_ns);  // no odometry beyond the data
}

TEST(Odometry, AZeroFusionStepIsAnErrorNamingTheField) {
  const Recording& rec = recording();
  Config config = deterministic_config();
  config.fusion.step_s = 0.0;
  for (const bool online : {false, true}) {
    try {
      if (online) {
        OnlineOdometry o(config, rec.T_imu_lidar, rec.gravity_m_s2);
      } else {
        Odometry o(config, rec.T_imu_lidar, rec.gravity_m_s2, rec.imu);
        o.process(rec.scans.front());
      }
      ADD_FAILURE() << (online ? "online" : "replay") << ": a zero step was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("fusion.step_s"), std::string::npos) << e.what();
    }
  }
}

namespace {

/// The frames of rec's first n scans handed to an OnlineOdometry whose worker is held in its
/// on_frame of the first scan while the others arrive, and released `hold` after the last:
/// (stamp, processed?) per scan, sorted by stamp; add_scan's answers in `accepted`.
std::vector<std::pair<std::int64_t, bool>> scans_into_a_held_worker(double max_wait_periods, std::size_t n,
                                                                    std::chrono::milliseconds hold,
                                                                    std::vector<bool>* accepted) {
  const Recording& rec = recording();
  Config config = deterministic_config();
  config.registration.max_wait_periods = max_wait_periods;
  std::mutex m;
  std::condition_variable cv;
  bool first_done = false, release = false;
  std::vector<std::pair<std::int64_t, bool>> frames;
  OnlineOdometry online(config, rec.T_imu_lidar, rec.gravity_m_s2, {}, [&](const OdometryFrame& f) {
    std::unique_lock lock(m);
    frames.emplace_back(f.scan.stamp_ns, f.processed);
    if (frames.size() == 1) {  // the worker, after the first scan: busy until released
      first_done = true;
      cv.notify_all();
      cv.wait(lock, [&] { return release; });
    }
  });
  accepted->push_back(online.add_scan(rec.scans[0]));
  {
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return first_done; });
  }
  for (std::size_t i = 1; i < n; ++i) accepted->push_back(online.add_scan(rec.scans[i]));
  std::this_thread::sleep_for(hold);
  {
    std::lock_guard lock(m);
    release = true;
  }
  cv.notify_all();
  online.wait_idle();
  online.stop();
  std::sort(frames.begin(), frames.end());
  return frames;
}

}  // namespace

TEST(OnlineOdometry, AScanArrivingWhileBusyWaitsBoundedAndTheNewestOfABurstWins) {
  using std::chrono::milliseconds;
  const Recording& rec = recording();
  const auto stamp = [&](std::size_t i) { return rec.scans[i].end_stamp_ns; };
  const std::int64_t period_ns = stamp(1) - stamp(0);
  // a burst of three scans while the worker is busy, released at once: the last one waits and is
  // processed, the two before it are dropped as busy (each replaced by a newer one)
  std::vector<bool> accepted;
  auto frames = scans_into_a_held_worker(1.0, 4, milliseconds(0), &accepted);
  EXPECT_EQ(accepted, (std::vector<bool>{true, true, true, true}));
  EXPECT_EQ(frames, (std::vector<std::pair<std::int64_t, bool>>{
                        {stamp(0), true}, {stamp(1), false}, {stamp(2), false}, {stamp(3), true}}));
  // a scan that waits longer than max_wait_periods is dropped when the worker comes to it
  accepted.clear();
  frames = scans_into_a_held_worker(0.5, 2, milliseconds(period_ns / 1'000'000 * 2), &accepted);
  EXPECT_EQ(accepted, (std::vector<bool>{true, true}));
  EXPECT_EQ(frames, (std::vector<std::pair<std::int64_t, bool>>{{stamp(0), true}, {stamp(1), false}}));
  // the paper's rule: every scan arriving while busy is dropped at once
  accepted.clear();
  frames = scans_into_a_held_worker(0.0, 4, milliseconds(0), &accepted);
  EXPECT_EQ(accepted, (std::vector<bool>{true, false, false, false}));
  EXPECT_EQ(frames, (std::vector<std::pair<std::int64_t, bool>>{
                        {stamp(0), true}, {stamp(1), false}, {stamp(2), false}, {stamp(3), false}}));
}

TEST(Replay, AScanArrivingWhileBusyWaitsUpToMaxWaitPeriods) {
  // a fixed latency of 1.45 scan periods (no tie between an arrival and the pipeline's end): a
  // scan that arrives while the pipeline is busy starts when it is free if that is at most
  // max_wait_periods later, else it is dropped; with 0 every scan arriving while busy is dropped
  const Recording& rec = recording();
  const std::int64_t period_ns = rec.scans[1].end_stamp_ns - rec.scans[0].end_stamp_ns;
  ReplayOptions slow;
  slow.latency = LatencyModel::Fixed;
  slow.fixed_latency_s = 1.45 * static_cast<double>(period_ns) * 1e-9;
  std::map<double, std::size_t> processed;
  for (const double max_wait : {0.0, 0.5, 1.0}) {
    Config config = deterministic_config();
    config.registration.max_wait_periods = max_wait;
    Odometry replay(config, rec.T_imu_lidar, rec.gravity_m_s2, rec.imu, slow);
    std::int64_t free_ns = 0;  // when the pipeline finishes the last processed scan
    for (std::size_t i = 0; i < rec.scans.size(); ++i) {
      const Scan& s = rec.scans[i];
      const OdometryFrame f = replay.process(s);
      const std::int64_t wait_ns = free_ns - s.end_stamp_ns;
      SCOPED_TRACE(testing::Message() << "max_wait " << max_wait << " scan " << i);
      if (wait_ns <= 0) {
        EXPECT_TRUE(f.processed);
        EXPECT_EQ(f.started_ns, s.end_stamp_ns);
      } else if (static_cast<double>(wait_ns) <= max_wait * static_cast<double>(period_ns)) {
        EXPECT_TRUE(f.processed);
        EXPECT_EQ(f.started_ns, free_ns);  // it waited for the pipeline
      } else {
        EXPECT_FALSE(f.processed);
        EXPECT_NE(f.drop_reason.find("still busy"), std::string::npos) << f.drop_reason;
      }
      if (f.processed) {
        EXPECT_LE(static_cast<double>(f.started_ns - s.end_stamp_ns), max_wait * static_cast<double>(period_ns));
        free_ns = f.available_ns;
      }
      processed[max_wait] += f.processed ? 1 : 0;
    }
  }
  // 1.45 periods: the paper's rule processes every other scan, waiting two of every three
  const std::size_t n = rec.scans.size();
  EXPECT_LE(processed[0.0], (n + 1) / 2);
  EXPECT_GE(processed[0.5], 2 * n / 3);
  EXPECT_GE(processed[1.0], 2 * n / 3);
}
