#include "farlio/pipeline/scan_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/time.hpp"
#include "farlio/map/adaptive_density.hpp"
#include "farlio/preprocess/preprocess.hpp"

namespace farlio::pipeline {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Writes the seconds from its construction to its end into a stage's field of FrameTimings.
class StageClock {
 public:
  explicit StageClock(double& seconds) : seconds_(seconds), start_(Clock::now()) {}
  ~StageClock() { seconds_ = seconds_since(start_); }
  StageClock(const StageClock&) = delete;
  StageClock& operator=(const StageClock&) = delete;

 private:
  double& seconds_;
  Clock::time_point start_;
};

// Used as the LiDAR period when neither stamps nor per-point times give one (10 Hz).
constexpr double kFallbackPeriod_s = 0.1;

/// The body twist per second ([v; w]) from `from` at from_ns to `to` at to_ns (zero unless to_ns is later).
registration::Vec6d twist_between(const SE3& from, const SE3& to, std::int64_t from_ns, std::int64_t to_ns) {
  if (to_ns <= from_ns) return registration::Vec6d::Zero();
  return (from.inverse() * to).log() / ns_to_seconds(to_ns - from_ns);
}

/// How far apart two motions over a scan put its first point (registration::model_error_m of the
/// difference of their poses at the scan start).
double motion_deviation_m(const deskew::ScanMotion& a, const deskew::ScanMotion& b, const ThresholdConfig& config) {
  const SE3 deviation = SE3::exp(a.offset.cast<double>()).inverse() * SE3::exp(b.offset.cast<double>());
  return registration::model_error_m(deviation, config);
}

}  // namespace

ScanPipeline::ScanPipeline(const Config& config, const SE3& initial_pose)
    : config_(validated(config)),
      backend_(make_scan_backend(config, &device_message_)),
      threshold_(config.threshold),
      initial_pose_(initial_pose),
      last_pose_(initial_pose),
      prev_pose_(initial_pose) {}

void ScanPipeline::reset_initial_pose(const SE3& initial_pose) {
  if (frames_ > 0) throw std::logic_error("ScanPipeline::reset_initial_pose after the first scan");
  initial_pose_ = last_pose_ = prev_pose_ = initial_pose;
}

void ScanPipeline::set_prior_map(std::vector<Eigen::Vector3f> world_points) {
  if (frames_ > 0) throw std::logic_error("ScanPipeline::set_prior_map after the first scan");
  prior_map_ = std::move(world_points);
  prior_map_loaded_ = false;
}

registration::Vec6d ScanPipeline::last_twist() const {
  if (frames_ < 2) return registration::Vec6d::Zero();
  return twist_between(prev_pose_, last_pose_, prev_stamp_ns_, last_stamp_ns_);
}

std::string ScanPipeline::register_frame(FrameResult& out, bool fused_guess, bool guess_confirmed,
                                         double time_budget_s) {
  // the spacing as the backends' maps hold it (float)
  const auto spacing_m = static_cast<float>(map::point_spacing_m(config_.map));
  const double p2p =
      registration::point_to_point_precision(config_.registration, config_.map.covariance_epsilon, spacing_m);
  // Degenerate directions are held only at a prediction from another sensor (the fusion's
  // guess): LiDAR-only, the constant-velocity model knows less than the scan's weak constraint
  // (racetrack launch seed 2: APE 1.12 m held there, 0.16 m not).
  RegistrationConfig reg = config_.registration;
  reg.hold_degenerate_directions = reg.hold_degenerate_directions && fused_guess;
  // The kernel scale sigma / 3 follows the constant-velocity model's deviations; the fusion's
  // guess deviates far less than sigma says (registration.fused_kernel_scale_m), and once it is
  // confirmed (the gyro's unit decided against the LiDAR) less still (confirmed_kernel_scale_m).
  registration::Thresholds thresholds = registration::Thresholds::from_sigma(out.sigma_m, p2p);
  if (fused_guess) {
    const double cap_m =
        guess_confirmed ? config_.registration.confirmed_kernel_scale_m : config_.registration.fused_kernel_scale_m;
    thresholds.kernel_scale_m = std::min(thresholds.kernel_scale_m, cap_m);
  }
  out.kernel_scale_m = thresholds.kernel_scale_m;
  out.registration = backend_->register_source(out.initial_guess, thresholds, reg, time_budget_s);
  out.registered = true;
  out.inlier_fraction = static_cast<double>(out.registration.system.inliers) / static_cast<double>(out.source_points);
  // The inlier-fraction bar catches a scan of something else (a bogus scan: random points pulled
  // the pose 1.8 m from the fusion's guess). A scan that sees more new space than mapped space (a
  // narrow field of view turning into a room of a young map: 9-50 % of the Avia's points matched
  // as the handheld cut's walker looks around) is as low, but registered from the fusion's guess
  // it stays within the kernel scale of it: then it stands.
  RegistrationConfig checks = config_.registration;
  if (fused_guess && (out.initial_guess.inverse() * out.registration.pose).translation().norm() <= out.kernel_scale_m)
    checks.min_inlier_fraction = 0.0;
  std::string failure = registration::failure_reason(out.registration, out.source_points, checks);
  if (failure.empty() && localizing() && out.inlier_fraction < config_.localization.min_inlier_fraction) {
    failure = "not localized: " + std::to_string(static_cast<int>(100.0 * out.inlier_fraction)) +
              " % of the points match the prior map (localization.min_inlier_fraction)";
  }
  return failure;
}

SE3 ScanPipeline::predict(std::int64_t stamp_ns) const {
  if (frames_ == 0) return initial_pose_;
  const double dt = ns_to_seconds(stamp_ns - last_stamp_ns_);
  return last_pose_ * SE3::exp(last_twist() * dt);
}

bool ScanPipeline::restart_map_after_failures(std::int64_t stamp_ns, const FrameResult& result) {
  if (result.failure.empty()) {
    failing_since_ns_.reset();
    return false;
  }
  if (!failing_since_ns_) failing_since_ns_ = stamp_ns;
  const double failing_s = ns_to_seconds(stamp_ns - *failing_since_ns_);
  if (result.kept_points == 0 || failing_s < config_.registration.map_restart_after_s) return false;
  backend_->reset(config_);
  failing_since_ns_.reset();
  return true;
}

FrameResult ScanPipeline::process(const Scan& input, const std::optional<SE3>& initial_guess,
                                  const std::optional<deskew::ScanMotion>& motion, bool guess_from_fusion,
                                  bool guess_confirmed) {
  auto t_start = Clock::now();
  FrameResult out;
  out.stamp_ns = input.end_stamp_ns;
  out.input_points = input.size();
  // points with NaN or Inf coordinates or times are dropped, as the readers drop them (a NaN time
  // has no place in the undistortion): by the backend, in its first pass over the scan, and here
  // before the scan that fixes the map's scale
  std::optional<Scan> finite;
  if (!scale_fixed_ && !input.all_finite()) {
    finite = input;
    out.non_finite_points = finite->remove_non_finite();
  }
  const Scan& scan = finite ? *finite : input;
  fix_scale(scan);              // 0. the first scan with points fixes the map's scale
  t_start += load_prior_map();  // localization: set-up, not this frame's work (the replay's latency)
  const deskew::ScanMotion scan_motion =
      motion ? *motion
             : deskew::ScanMotion::constant_twist(last_twist().cast<float>(), static_cast<float>(scan.duration_s()));
  preprocess(scan, scan_motion, out);                                                        // 1.
  const map::PointLimit limit = build_source(out);                                           // 2.
  register_scan(scan, scan_motion, initial_guess, guess_from_fusion, guess_confirmed, out);  // 3.
  update_map(scan.end_stamp_ns, limit, out);                                                 // 4.
  advance(scan.end_stamp_ns, out.pose, out);                                                 // 5.
  backend_->device_stage_times(out.timings);
  out.timings.total_s = seconds_since(t_start);
  return out;
}

void ScanPipeline::fix_scale(const Scan& scan) {
  if (scale_fixed_ || scan.empty()) return;
  scale_fixed_ = true;
  const double voxel = preprocess::scene_voxel_size_m(scan.points, config_.map);
  if (voxel != config_.map.voxel_size_m) {
    config_.map.voxel_size_m = voxel;
    backend_->reset(config_);
  }
  config_.map.auto_voxel_size = false;  // the effective config states the size used
}

std::chrono::steady_clock::duration ScanPipeline::load_prior_map() {
  if (!prior_map_ || prior_map_loaded_ || !scale_fixed_) return Clock::duration::zero();
  const auto t0 = Clock::now();
  backend_->load_map(*prior_map_);  // at the scale fixed
  prior_map_loaded_ = true;
  return Clock::now() - t0;
}

void ScanPipeline::preprocess(const Scan& scan, const deskew::ScanMotion& scan_motion, FrameResult& out) {
  // crop, undistort into the scan-end frame, downsample to the map spacing
  const StageClock clock(out.timings.preprocess_s);
  const bool undistort = config_.preprocess.undistort && scan.has_time() && !scan_motion.is_identity();
  out.motion = scan_motion;
  out.undistorted = undistort;
  out.kept_points = backend_->preprocess(scan, scan_motion, undistort);
  out.non_finite_points += backend_->non_finite_points();
}

map::PointLimit ScanPipeline::build_source(FrameResult& out) {
  // source covariances from the per-scan frame map (sensor frame), and the scan's density, which
  // sets the submap's limit (ASMD); without a submap (the first scan) nothing reads the
  // covariances: the frame map without them (KITTI's first frame: this stage 0.5 ms on 2 threads
  // instead of 1.6 ms, docs/performance.md)
  const StageClock clock(out.timings.covariance_s);
  const SourceSummary source = backend_->build_source(config_.density.close_range_m, backend_->map_voxels() > 0);
  out.source_points = source.points;
  const map::PointLimit limit = map::adaptive_point_limit(source.mean_points_per_voxel, config_.density, config_.map);
  out.density_limit = limit.close_limit;
  return limit;
}

void ScanPipeline::register_scan(const Scan& scan, const deskew::ScanMotion& scan_motion,
                                 const std::optional<SE3>& initial_guess, bool guess_from_fusion, bool guess_confirmed,
                                 FrameResult& out) {
  const StageClock clock(out.timings.registration_s);
  const double period_s = frames_ > 0 && scan.end_stamp_ns > last_stamp_ns_
                              ? ns_to_seconds(scan.end_stamp_ns - last_stamp_ns_)
                              : (scan.duration_s() > 0 ? scan.duration_s() : kFallbackPeriod_s);
  out.initial_guess = initial_guess ? *initial_guess : predict(scan.end_stamp_ns);
  // The first registration has no motion model: its constant-velocity guess assumes rest. A body
  // that already moves (a recording cut at speed: 3.5 m a scan at 70 m/s and 20 Hz) is found
  // with correspondences as far as the adaptive threshold's cap.
  const bool fused_guess = initial_guess.has_value() && guess_from_fusion;
  const bool motion_unknown = frames_ == 1 && !fused_guess && !localizing();
  out.sigma_m = motion_unknown
                    ? std::max(threshold_.sigma_m(), registration::sigma_without_motion_model_m(config_.threshold))
                    : threshold_.sigma_m();
  out.pose = out.initial_guess;
  if (backend_->map_voxels() > 0 && out.source_points > 0) {
    const double time_budget_s = config_.registration.time_budget_factor * period_s;
    out.failure = register_frame(out, fused_guess, fused_guess && guess_confirmed, time_budget_s);
    if (out.failure.empty()) {
      out.pose = out.registration.pose;
      threshold_.update(out.initial_guess.inverse() * out.pose);
    }
    if (motion_unknown && out.failure.empty()) restart_map_with_found_motion(scan, scan_motion, out);
  } else if (backend_->map_voxels() > 0) {
    out.failure = "nothing to register against (no points after preprocessing)";
  }
  out.lost = localizing() && !out.failure.empty();
}

void ScanPipeline::restart_map_with_found_motion(const Scan& scan, const deskew::ScanMotion& scan_motion,
                                                 FrameResult& out) {
  // The first scan and this one were undistorted without the motion just found. Both are smeared
  // alike, so the registration of one against the other stands; the map starts again from this
  // scan undistorted with that motion (the first scan leaves it).
  if (!config_.preprocess.undistort || !scan.has_time()) return;
  const deskew::ScanMotion found = deskew::ScanMotion::constant_twist(
      twist_between(last_pose_, out.pose, last_stamp_ns_, scan.end_stamp_ns).cast<float>(),
      static_cast<float>(scan.duration_s()));
  if (motion_deviation_m(scan_motion, found, config_.threshold) <= config_.threshold.min_motion_m) return;
  out.motion = found;
  out.undistorted = true;
  out.kept_points = backend_->preprocess(scan, found, true);
  out.source_points = backend_->build_source(config_.density.close_range_m, false).points;
  backend_->reset(config_);
  out.map_started_here = true;
}

void ScanPipeline::update_map(std::int64_t stamp_ns, const map::PointLimit& limit, FrameResult& out) {
  // submap update with the adaptive density, then removal of far voxels. A failed scan changes
  // nothing, unless failures have lasted map_restart_after_s: then the map restarts from this
  // scan at the prediction (recovery when the old map no longer matches). A prior map
  // (localization) is held fixed.
  const StageClock clock(out.timings.map_update_s);
  if (!localizing()) {
    out.map_restarted = restart_map_after_failures(stamp_ns, out);
    if (out.failure.empty() || out.map_restarted)
      out.map_insert = backend_->update_map(out.pose, limit, &out.removed_voxels);
  }
  out.map_voxels = backend_->map_voxels();
  out.map_points = backend_->map_points();
}

void ScanPipeline::advance(std::int64_t stamp_ns, const SE3& pose, FrameResult& out) {
  // velocity from consecutive poses (eq. 6) and the constant-velocity state
  if (frames_ > 0 && stamp_ns > last_stamp_ns_) {
    const double dt = ns_to_seconds(stamp_ns - last_stamp_ns_);
    out.velocity_body_m_s = velocity_from_poses(last_pose_, pose, dt);
    out.angular_velocity_body_rad_s = (last_pose_.inverse() * pose).log().tail<3>() / dt;
  }
  prev_pose_ = last_pose_;
  prev_stamp_ns_ = last_stamp_ns_;
  last_pose_ = pose;
  last_stamp_ns_ = stamp_ns;
  ++frames_;
}

}  // namespace farlio::pipeline
