#pragma once
// The whole map of a run, for export (`farlio run --save-map`): every scan whose pose was used,
// undistorted and placed at its registered pose, voxel-downsampled to one point per cell of
// `resolution_m` (the centroid of all the points that fell into the cell over the run, with their
// mean intensity). The submap the registration uses keeps only map.removal_radius_m around the
// sensor; this keeps every place visited.
//
// Memory: one entry per occupied cell, not the points. With a spill folder, the cells are grouped
// in cubic tiles of `tile_m`, and a tile the sensor has left behind (farther than the range crop
// plus a tile can reach) is written to its own file there and dropped from memory; it is read back
// when the sensor comes near it again, before the scan's points are added, so a cell is either in
// memory or on disk, never both. Memory is then bounded by the tiles around the sensor, whatever
// the run's length; the files are removed with the MapExport. for_each_piece streams the whole
// map, tile by tile, to a writer.
//
// The points go through the preprocessing's per-point bodies (preprocess_point.hpp: range crop and
// undistortion with the motion the pipeline used), so the map holds what the registration saw.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <unordered_map>
#include <unordered_set>
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
  /// Throws std::invalid_argument unless resolution_m is in [kMinVoxelSize_m, kMaxVoxelSize_m] and
  /// tile_m is at least resolution_m. The per-point work runs on num_threads (0: all), the
  /// accumulation on the caller's thread. `spill_dir` empty: every cell stays in memory; else the
  /// folder (created) where tiles left behind are kept.
  MapExport(double resolution_m, const PreprocessConfig& preprocess, int num_threads = 0,
            std::filesystem::path spill_dir = {}, double tile_m = 64.0);
  ~MapExport();
  MapExport(const MapExport&) = delete;
  MapExport& operator=(const MapExport&) = delete;

  /// Adds `scan` (LiDAR frame, raw) undistorted with `motion` (when `undistort`) and placed at
  /// `pose` (the LiDAR pose at the scan end in the world). Returns the points added (cropped,
  /// non-finite and out-of-key-range points are not).
  std::size_t add(const Scan& scan, const deskew::ScanMotion& motion, bool undistort, const SE3& pose);

  /// Calls piece(points, intensities) for the cells in memory, then for each tile on disk (read
  /// back one at a time), each piece ordered by cell key: the whole map, one point per cell.
  void for_each_piece(const std::function<void(std::span<const Vec3f>, std::span<const float>)>& piece) const;
  /// The whole map in one Scan (for_each_piece gathered: holds it all in memory).
  [[nodiscard]] Scan points() const;
  /// Cells of the whole map (in memory and on disk), and in memory only.
  [[nodiscard]] std::size_t cells() const { return cells_.size() + cells_on_disk_; }
  [[nodiscard]] std::size_t cells_in_memory() const { return cells_.size(); }
  [[nodiscard]] std::size_t tiles_on_disk() const { return tiles_on_disk_.size(); }
  [[nodiscard]] std::size_t points_added() const { return points_added_; }
  [[nodiscard]] double resolution_m() const { return resolution_m_; }
  /// Bytes of the cells held in memory (entries, their nodes and the buckets).
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  /// Sums relative to the cell's corner (float keeps its precision far from the origin).
  struct Cell {
    float dx = 0, dy = 0, dz = 0, intensity = 0;
    std::uint32_t count = 0;
  };
  using Cells = std::unordered_map<std::uint64_t, Cell>;
  [[nodiscard]] std::uint64_t tile_of(std::uint64_t cell_key) const;
  [[nodiscard]] Eigen::Vector3d tile_center(std::uint64_t tile_key) const;
  [[nodiscard]] std::filesystem::path tile_path(std::uint64_t tile_key) const;
  /// Tiles on disk within reach of a scan from `sensor` come back into memory.
  void reload_near(const Eigen::Vector3d& sensor);
  /// Tiles in memory beyond reach (with a tile of hysteresis) go to disk.
  void spill_far(const Eigen::Vector3d& sensor);
  [[nodiscard]] Cells read_tile(std::uint64_t tile_key) const;
  /// Centroids and mean intensities of `cells`, ordered by key, to `piece`.
  void emit(const Cells& cells, const std::function<void(std::span<const Vec3f>, std::span<const float>)>& piece) const;

  double resolution_m_;
  PreprocessConfig preprocess_;
  Cells cells_;
  std::size_t points_added_ = 0;
  exec::CpuExecutor executor_;
  // spilling (off when spill_dir_ is empty)
  std::filesystem::path spill_dir_;
  double tile_m_;
  double reach_m_;  ///< a tile whose centre is within this of the sensor can receive points
  std::unordered_map<std::uint64_t, std::size_t> tile_cells_;     ///< cells in memory per tile
  std::unordered_map<std::uint64_t, std::size_t> tiles_on_disk_;  ///< tile -> cells in its file
  std::size_t cells_on_disk_ = 0;
  // per-scan buffers, reused: each point's cell key and its offset from the cell's corner
  std::vector<std::uint64_t> keys_;
  std::vector<Eigen::Vector3f> offsets_;
};

}  // namespace farlio::pipeline
