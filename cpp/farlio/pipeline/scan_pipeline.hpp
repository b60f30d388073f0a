#pragma once
// The LiDAR scan pipeline of the paper (Fig. 2, left half), one call per scan:
//   preprocess (range crop, undistortion, downsampling to the map spacing)
//   -> source covariances (per-scan frame map, which also measures the scan's density)
//   -> sparsity-aware GICP against the adaptive local submap
//   -> submap update (adaptive density) and removal of far voxels
//   -> pose and velocity out (eq. 6).
// The initial guess and the motion during the scan come from the sensor fusion when given;
// otherwise from a constant-velocity model (LiDAR-only odometry). Poses are of the LiDAR frame
// at the scan's end stamp. The stages run on a ScanBackend (CPU executor or CUDA, chosen by
// config.device).
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"
#include "farlio/deskew/scan_motion.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/pipeline/frame_timings.hpp"
#include "farlio/pipeline/scan_backend.hpp"
#include "farlio/registration/adaptive_threshold.hpp"
#include "farlio/registration/gicp.hpp"

namespace farlio::pipeline {

struct FrameResult {
  std::int64_t stamp_ns = 0;                                    ///< scan end stamp
  SE3 pose;                                                     ///< LiDAR pose in the world at the scan end
  SE3 initial_guess;                                            ///< the guess the registration started from
  Eigen::Vector3d velocity_body_m_s = Eigen::Vector3d::Zero();  ///< eq. (6)
  Eigen::Vector3d angular_velocity_body_rad_s = Eigen::Vector3d::Zero();
  registration::RegistrationResult registration;
  bool registered = false;  ///< false for the first scan (it starts the map)
  /// Why the registration's pose was not used (empty when it was): too few inliers, a
  /// non-finite pose. The scan then keeps the predicted pose and changes no state.
  std::string failure;
  bool map_restarted = false;  ///< the map was restarted from this scan (after failures, recovery)
  /// The first registration found the body moving: this scan was undistorted again with that
  /// motion and the map started again from it (the first scan, undistorted without it, left).
  bool map_started_here = false;
  /// Inliers over source points of the registration (0 when not registered).
  double inlier_fraction = 0;
  /// Localization in a prior map: the scan did not match the map (a failure, or an inlier
  /// fraction below localization.min_inlier_fraction); its pose is the prediction.
  bool lost = false;
  deskew::ScanMotion motion;  ///< the motion the scan was undistorted with
  bool undistorted = false;   ///< whether it was (per-point times, preprocess.undistort, motion)
  double sigma_m = 0;         ///< adaptive threshold used
  double kernel_scale_m = 0;  ///< Cauchy kernel scale used (sigma / 3, or registration.fused_kernel_scale_m)
  int density_limit = 0;      ///< close-range per-voxel limit chosen by ASMD
  std::size_t input_points = 0, kept_points = 0, source_points = 0;
  /// Points dropped before the preprocessing for NaN or Inf coordinates or times (the readers
  /// drop them; a scan handed to the API may still have them).
  std::size_t non_finite_points = 0;
  map::InsertStats map_insert;
  std::size_t map_voxels = 0, map_points = 0, removed_voxels = 0;
  FrameTimings timings;
};

/// Eq. (6): the velocity in the frame of `current`, from the translation between two poses dt_s
/// apart.
inline Eigen::Vector3d velocity_from_poses(const SE3& previous, const SE3& current, double dt_s) {
  return current.rotation().transpose() * (current.translation() - previous.translation()) / dt_s;
}

class ScanPipeline {
 public:
  /// `initial_pose`: pose of the LiDAR in the world at the first scan. Throws when config.device
  /// is cuda and no CUDA device can be had.
  explicit ScanPipeline(const Config& config, const SE3& initial_pose = SE3());

  /// Registers one scan. `initial_guess` (world pose at the scan end) and `motion` (for the
  /// undistortion) come from the fusion; when absent, the constant-velocity model supplies them.
  /// guess_from_fusion false: the guess is a LiDAR-only one (the constant-velocity translation
  /// with the gyro's rotation, before the filter is initialised) and registered as such.
  /// guess_confirmed: the fusion's guess is confirmed (ScanPrior::confirmed): the kernel scale is
  /// capped at registration.confirmed_kernel_scale_m instead of fused_kernel_scale_m.
  /// Points with NaN or Inf coordinates or times are dropped (FrameResult::non_finite_points).
  FrameResult process(const Scan& input, const std::optional<SE3>& initial_guess = std::nullopt,
                      const std::optional<deskew::ScanMotion>& motion = std::nullopt, bool guess_from_fusion = true,
                      bool guess_confirmed = false);

  /// The scan that process() will be given after the next one, so that the backend can move it
  /// towards its device while it works (the CUDA backend uploads it during the next frame's
  /// kernels: offline, scans back to back, the upload leaves the frame's time). `next` must stay
  /// alive and unchanged until process() of it, the next stage_next() or the pipeline's end; a
  /// scan other than the staged one (or one the pipeline screens first) is uploaded in its own
  /// frame, as without staging.
  void stage_next(const Scan& next) { backend_->stage_next(next); }

  /// Replaces the initial pose; only before the first scan (throws std::logic_error after).
  void reset_initial_pose(const SE3& initial_pose);

  /// Localization: the submap is built from `world_points` (a prior map, in the world frame of
  /// the poses) at the first scan, once the voxel size is fixed, and then held fixed: scans are
  /// registered against it and never inserted, nothing is removed, failures do not restart it.
  /// Only before the first scan (throws std::logic_error after).
  void set_prior_map(std::vector<Eigen::Vector3f> world_points);
  [[nodiscard]] bool localizing() const { return prior_map_.has_value(); }

  /// The backend that runs the stages (its submap, memory and device).
  [[nodiscard]] const ScanBackend& backend() const { return *backend_; }
  [[nodiscard]] ScanBackend& backend() { return *backend_; }
  /// Why device auto fell back to the CPU (empty when it did not).
  [[nodiscard]] const std::string& device_message() const { return device_message_; }
  /// The effective parameters (the voxel size is fixed at the first scan when auto).
  [[nodiscard]] const Config& config() const { return config_; }
  [[nodiscard]] std::size_t frames() const { return frames_; }
  /// The constant-velocity prediction for a scan ending at stamp_ns (the LiDAR-only guess).
  [[nodiscard]] SE3 predict(std::int64_t stamp_ns) const;
  /// Body twist per second ([v; w]) between the last two registered poses.
  [[nodiscard]] registration::Vec6d last_twist() const;

 private:
  // The steps of process(), in order (paper Fig. 2):
  /// The first scan with points fixes the map's voxel size (map.auto_voxel_size).
  void fix_scale(const Scan& scan);
  /// Localization: loads the prior map once the scale is fixed; returns how long that took.
  std::chrono::steady_clock::duration load_prior_map();
  /// 1. Crop, undistortion with scan_motion, downsampling (out: motion, undistorted, kept_points).
  void preprocess(const Scan& scan, const deskew::ScanMotion& scan_motion, FrameResult& out);
  /// 2. The source and its covariances; returns the submap's per-voxel limit (ASMD).
  map::PointLimit build_source(FrameResult& out);
  /// 3. Registration against the submap from the fusion's guess or the constant-velocity
  /// prediction (out: initial_guess, sigma_m, pose, failure, lost, ...).
  void register_scan(const Scan& scan, const deskew::ScanMotion& scan_motion, const std::optional<SE3>& initial_guess,
                     bool guess_from_fusion, bool guess_confirmed, FrameResult& out);
  /// After the first registration: when it found the body moving, this scan is undistorted again
  /// with that motion and the map starts again from it (out.map_started_here).
  void restart_map_with_found_motion(const Scan& scan, const deskew::ScanMotion& scan_motion, FrameResult& out);
  /// 4. Submap update with the limit, removal of far voxels, restart after lasting failures.
  void update_map(std::int64_t stamp_ns, const map::PointLimit& limit, FrameResult& out);
  /// 5. Velocity from consecutive poses (eq. 6), and the constant-velocity state moves on.
  void advance(std::int64_t stamp_ns, const SE3& pose, FrameResult& out);
  /// GICP of the frame's source from out.initial_guess at out.sigma_m (sets out.registration,
  /// registered, inlier_fraction, kernel_scale_m) over out.source_points; returns why its pose must
  /// not be used (empty when it may). fused_guess: the guess is the fusion's.
  std::string register_frame(FrameResult& out, bool fused_guess, bool guess_confirmed, double time_budget_s);
  /// Tracks failures in a row; after map_restart_after_s of them, empties the submap (a scan with
  /// points then starts it again) and returns true.
  bool restart_map_after_failures(std::int64_t stamp_ns, const FrameResult& result);

  Config config_;
  std::string device_message_;
  std::unique_ptr<ScanBackend> backend_;
  registration::AdaptiveThreshold threshold_;
  SE3 initial_pose_;
  SE3 last_pose_, prev_pose_;
  std::int64_t last_stamp_ns_ = 0, prev_stamp_ns_ = 0;
  std::size_t frames_ = 0;
  bool scale_fixed_ = false;
  std::optional<std::int64_t> failing_since_ns_;           ///< scan end of the first failure in a row
  std::optional<std::vector<Eigen::Vector3f>> prior_map_;  ///< localization: the map held fixed
  bool prior_map_loaded_ = false;
};

}  // namespace farlio::pipeline
