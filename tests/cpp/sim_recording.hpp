#pragma once
// A generated recording held in memory for the odometry tests: scans thinned to keep sanitizer
// runs short, the IMU, the extrinsic and gravity; and a config whose results do not depend on
// how fast the machine is.
#include <tbb/task_arena.h>

#include <limits>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"
#include "farlio/sim/sequence_generator.hpp"

namespace farlio::test {

#if defined(__SANITIZE_THREAD__)
/// ThreadSanitizer does not see the synchronisation inside Debian's TBB (not instrumented), so it
/// would report every hand-over between TBB's workers and the caller. Under TSan the odometry
/// tests run one thread per TBB arena (no TBB worker starts), and TSan checks farlio's own
/// threads: OnlineOdometry's worker, the IMU and scan threads, the callbacks (docs/development.md).
inline constexpr bool kThreadSanitized = true;
#else
inline constexpr bool kThreadSanitized = false;
#endif
/// config.num_threads of the odometry tests: all (0), or one under TSan.
inline constexpr int kPipelineThreads = kThreadSanitized ? 1 : 0;

struct Recording {
  std::vector<Scan> scans;
  std::vector<ImuSample> imu;
  std::vector<SE3> body_at_scan_end;  ///< ground truth
  SE3 T_imu_lidar;
  double gravity_m_s2 = 0;
};

/// Every k-th point of a scan with its time, intensity and sensor id.
inline Scan thinned(const Scan& s, std::size_t k) {
  Scan out;
  out.start_stamp_ns = s.start_stamp_ns;
  out.end_stamp_ns = s.end_stamp_ns;
  for (std::size_t i = 0; i < s.size(); i += k) {
    out.points.push_back(s.points[i]);
    if (!s.time_s.empty()) out.time_s.push_back(s.time_s[i]);
    if (!s.intensity.empty()) out.intensity.push_back(s.intensity[i]);
    if (!s.sensor_id.empty()) out.sensor_id.push_back(s.sensor_id[i]);
  }
  return out;
}

/// `duration_s` of a profile from `motion_start_s` into its motion, every `keep_every`-th point of
/// each scan, with the profile's own LiDAR or a named model.
inline Recording record(sim::Profile profile, double duration_s, std::size_t keep_every, double motion_start_s = 0.0,
                        sim::LidarModel lidar_model = sim::LidarModel::Profile) {
  sim::SimConfig cfg = sim::default_config(profile);
  cfg.duration_s = duration_s;
  cfg.motion_start_s = motion_start_s;
  cfg.lidar_model = lidar_model;
  const sim::SequenceGenerator gen(cfg);
  Recording r;
  // the generator's TBB loops: in an arena of one thread under TSan (kThreadSanitized)
  tbb::task_arena arena(kThreadSanitized ? 1 : tbb::task_arena::automatic);
  arena.execute([&] {
    for (std::size_t i = 0; i < gen.num_scans(); ++i) r.scans.push_back(thinned(gen.scan(i), keep_every));
  });
  for (const auto& p : gen.groundtruth_scans()) r.body_at_scan_end.push_back(p.pose);
  r.imu = gen.imu();
  r.T_imu_lidar = gen.T_imu_lidar();
  r.gravity_m_s2 = gen.gravity_m_s2();
  return r;
}

/// Scans [first, first + count) of a profile's generated sequence, whole, with its own LiDAR.
inline std::vector<Scan> generated_scans(sim::Profile profile, std::size_t first, std::size_t count) {
  sim::SimConfig cfg = sim::default_config(profile);
  cfg.duration_s = static_cast<double>(first + count + 1) / cfg.lidar_rate_hz;
  const sim::SequenceGenerator gen(cfg);
  std::vector<Scan> scans;
  for (std::size_t i = first; i < first + count; ++i) scans.push_back(gen.scan(i));
  return scans;
}

/// How far a run's body position at the last scan is from the truth, both taken relative to the
/// first scan (the run's own start and the recording's): the end drift of the motion estimated.
inline double final_position_error_m(const Recording& rec, const SE3& first_body, const SE3& last_body) {
  const SE3 truth = rec.body_at_scan_end.front().inverse() * rec.body_at_scan_end.back();
  const SE3 estimate = first_body.inverse() * last_body;
  return (truth.translation() - estimate.translation()).norm();
}

/// Results that do not depend on how fast this machine is: no registration time budget (a slow
/// sanitizer build would otherwise drop frames the replay keeps, or the other way round).
inline Config deterministic_config() {
  Config c;
  c.num_threads = kPipelineThreads;
  c.registration.time_budget_factor = std::numeric_limits<double>::infinity();
  return c;
}

}  // namespace farlio::test
