#pragma once
// The compute backend of the scan pipeline: where the scan, the frame map, the source cloud and
// the submap live and where the per-point bodies run (CPU executor or CUDA). ScanPipeline keeps
// the logic between the stages (guesses, thresholds, density, velocity) on the host and calls
// one backend method per stage.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/device.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"
#include "farlio/deskew/scan_motion.hpp"
#include "farlio/map/map_snapshot.hpp"
#include "farlio/map/point_limit.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/pipeline/frame_timings.hpp"
#include "farlio/registration/gicp.hpp"

namespace farlio::pipeline {

/// The source cloud of a frame and the scan's density measured on its frame map.
struct SourceSummary {
  std::size_t points = 0;
  double mean_points_per_voxel = 0.0;  ///< over frame-map voxels within the density range
};

class ScanBackend {
 public:
  virtual ~ScanBackend() = default;
  [[nodiscard]] virtual Device device() const = 0;
  /// Empties both maps and takes the map parameters of `config` (the voxel size is fixed at the
  /// first scan). Allocates nothing on the CUDA backend.
  virtual void reset(const Config& config) = 0;
  /// The scan after the one the next preprocess() will be given, handed over before that frame's
  /// stages: a backend may start moving it towards its device while it works on the frame (the
  /// CUDA backend uploads it on a stream of its own; the CPU backend has nothing to move). `next`
  /// must stay alive and unchanged until its own preprocess(), the next stage_next() or the
  /// backend's end; a scan other than the staged one is preprocessed as usual.
  virtual void stage_next(const Scan& next) { (void)next; }
  /// Whether the last preprocess() found its scan staged by stage_next (already on its way).
  [[nodiscard]] virtual bool last_scan_was_staged() const { return false; }
  /// Drops the points with a NaN or Inf coordinate or time (preprocess::finite_point), range
  /// crop, undistortion into the scan-end frame (when `undistort`), downsampling to the map
  /// spacing. Keeps the frame; returns its size.
  virtual std::size_t preprocess(const Scan& scan, const deskew::ScanMotion& motion, bool undistort) = 0;
  /// The points that the last preprocess dropped for a NaN or Inf coordinate or time: counted in
  /// the backend's own first pass over the scan, not in a pass of its own (a scan not in the
  /// caches: 0.1-0.3 ms for 120-210k points on the H100's host, a quarter of a GPU frame).
  [[nodiscard]] virtual std::size_t non_finite_points() const = 0;
  /// The per-scan frame map of the frame (sensor frame), the source cloud with its covariances,
  /// and the mean points per frame-map voxel within `density_range_m` of the sensor. Without
  /// `covariances` (nothing to register against: an empty submap) the source has the same
  /// points, none with a covariance.
  virtual SourceSummary build_source(double density_range_m, bool covariances) = 0;
  /// Sparsity-aware GICP of the source against the submap.
  virtual registration::RegistrationResult register_source(const SE3& initial_guess, const registration::Thresholds& th,
                                                           const RegistrationConfig& config, double time_budget_s) = 0;
  /// Inserts the frame at `pose` into the submap, then removes voxels far from the pose.
  virtual map::InsertStats update_map(const SE3& pose, const map::PointLimit& limit, std::size_t* removed_voxels) = 0;
  /// Inserts world-frame points into the submap with the full per-voxel limit and removes
  /// nothing (a prior map for localization; after reset, before the first scan's registration).
  virtual void load_map(const std::vector<Eigen::Vector3f>& world_points) = 0;
  [[nodiscard]] virtual std::size_t map_voxels() const = 0;
  [[nodiscard]] virtual std::size_t map_points() const = 0;
  /// Bytes held for the submap (CPU) or all device buffers (CUDA, preallocated).
  [[nodiscard]] virtual std::size_t memory_bytes() const = 0;
  /// A host copy of the submap.
  [[nodiscard]] virtual map::MapSnapshot map_snapshot() const = 0;
  /// A host copy of the last preprocessed frame: the kept points, undistorted, in the sensor
  /// frame at the scan end (what update_map inserts).
  [[nodiscard]] virtual std::vector<Eigen::Vector3f> frame_points() const = 0;
  /// Replaces the wall-clock stage times of the frame just processed by device-measured ones;
  /// false (and `t` untouched) on a backend without device timers.
  virtual bool device_stage_times(FrameTimings& t) {
    (void)t;
    return false;
  }
};

/// Voxels the CPU frame map preallocates (a scan fills ~1-2k; the pool doubles as needed).
inline constexpr std::int64_t kFrameMapInitialVoxels = 1024;

/// The frame map's parameters: the submap's spacing (the scan is downsampled to it) with the
/// frame map's lower cap, no refresh, no removal. Inline: the CUDA backend (farlio_cuda, below
/// the factory's library) uses it too.
inline VoxelMapConfig frame_map_config(const Config& c) {
  VoxelMapConfig f = c.map;
  // the frame map keeps the submap's spacing (the scan is downsampled to it) with a lower cap
  f.point_spacing_m = map::point_spacing_m(c.map);
  f.max_points_per_voxel = c.density.frame_map_max_points_per_voxel;
  f.refresh_covariances = false;
  f.removal_radius_m = std::numeric_limits<double>::infinity();
  // sized for one scan (~1-2k voxels, the pool doubles as needed), not for the submap: the
  // per-frame clear and the voxel lookups touch a table of a few thousand slots, not 32k
  f.initial_voxel_capacity = std::min<std::int64_t>(c.map.initial_voxel_capacity, kFrameMapInitialVoxels);
  return f;
}

/// The backend for config.device (auto resolved by resolve_device; `message` explains a
/// fallback to the CPU). Throws when cuda is asked for and cannot be had.
std::unique_ptr<ScanBackend> make_scan_backend(const Config& config, std::string* message = nullptr);

}  // namespace farlio::pipeline
