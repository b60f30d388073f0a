#pragma once
// The whole map of a run, for export (`farlio run --save-map`): every scan whose pose was used,
// undistorted and placed at its registered pose, voxel-downsampled to one point per cell of
// `resolution_m` (the centroid of all the points that fell into the cell over the run, with their
// mean intensity). The submap the registration uses keeps only map.removal_radius_m around the
// sensor; this keeps every place visited. It holds one cell per occupied voxel, not the points,
// so its memory grows with the mapped volume and not with the run's length: a second lap over
// the same road adds nothing.
//
// The points go through the preprocessing's per-point body (preprocess_point.hpp: range crop and
// undistortion with the motion the pipeline used), so the map holds what the registration saw.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"
#include "farlio/deskew/scan_motion.hpp"
#include "farlio/exec/cpu_executor.hpp"

namespace farlio::pipeline {

/// The export resolution of `config`: map.export_resolution_m, or the map's point spacing when 0.
double export_resolution_m(const Config& config);

class MapExport {
 public:
  /// Throws std::invalid_argument unless resolution_m is in [kMinVoxelSize_m, kMaxVoxelSize_m].
  /// The per-point work runs on num_threads (0: all), the accumulation on the caller's thread.
  MapExport(double resolution_m, const PreprocessConfig& preprocess, int num_threads = 0);

  /// Adds `scan` (LiDAR frame, raw) undistorted with `motion` (when `undistort`) and placed at
  /// `pose` (the LiDAR pose at the scan end in the world). Returns the points added (cropped,
  /// non-finite and out-of-key-range points are not).
  std::size_t add(const Scan& scan, const deskew::ScanMotion& motion, bool undistort, const SE3& pose);

  /// The map: one point per cell (centroid, mean intensity), ordered by cell key.
  [[nodiscard]] Scan points() const;
  [[nodiscard]] std::size_t cells() const { return cells_.size(); }
  [[nodiscard]] std::size_t points_added() const { return points_added_; }
  [[nodiscard]] double resolution_m() const { return resolution_m_; }
  /// Bytes of the cell table (entries, their nodes and the buckets).
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  /// Sums relative to the cell's corner (float keeps its precision far from the origin).
  struct Cell {
    float dx = 0, dy = 0, dz = 0, intensity = 0;
    std::uint32_t count = 0;
  };
  double resolution_m_;
  PreprocessConfig preprocess_;
  std::unordered_map<std::uint64_t, Cell> cells_;
  std::size_t points_added_ = 0;
  exec::CpuExecutor executor_;
  // per-scan buffers, reused: each point's cell key and its offset from the cell's corner
  std::vector<std::uint64_t> keys_;
  std::vector<Eigen::Vector3f> offsets_;
};

}  // namespace farlio::pipeline
