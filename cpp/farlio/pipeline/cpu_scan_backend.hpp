#pragma once
// The scan pipeline's stages on the CPU executor (TBB arena of config.num_threads threads)
// over host voxel maps.
#include <cstdint>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/pipeline/scan_backend.hpp"
#include "farlio/preprocess/cell_downsampler.hpp"

namespace farlio::pipeline {

class CpuScanBackend final : public ScanBackend {
 public:
  explicit CpuScanBackend(const Config& config);

  [[nodiscard]] Device device() const override { return Device::Cpu; }
  void reset(const Config& config) override;
  std::size_t preprocess(const Scan& scan, const deskew::ScanMotion& motion, bool undistort) override;
  [[nodiscard]] std::size_t non_finite_points() const override { return non_finite_points_; }
  SourceSummary build_source(double density_range_m, bool covariances) override;
  registration::RegistrationResult register_source(const SE3& initial_guess, const registration::Thresholds& th,
                                                   const RegistrationConfig& config, double time_budget_s) override;
  map::InsertStats update_map(const SE3& pose, const map::PointLimit& limit, std::size_t* removed_voxels) override;
  void load_map(const std::vector<Eigen::Vector3f>& world_points) override;
  [[nodiscard]] std::size_t map_voxels() const override { return map_.num_voxels(); }
  [[nodiscard]] std::size_t map_points() const override { return map_.num_points(); }
  [[nodiscard]] std::size_t memory_bytes() const override { return map_.memory_bytes(); }
  [[nodiscard]] map::MapSnapshot map_snapshot() const override { return map_.snapshot(); }
  [[nodiscard]] std::vector<Eigen::Vector3f> frame_points() const override { return frame_; }

 private:
  Config config_;
  exec::CpuExecutor executor_;
  map::VoxelMap map_;
  map::VoxelMap frame_map_;
  preprocess::CellDownsampler downsampler_;
  std::vector<Eigen::Vector3f> frame_;  // the kept points (sensor frame, scan end)
  std::size_t non_finite_points_ = 0;   // of the last scan
  registration::SourceCloud source_;
};

}  // namespace farlio::pipeline
