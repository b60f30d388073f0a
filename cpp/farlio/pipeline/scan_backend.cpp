#include "farlio/pipeline/scan_backend.hpp"

#include <algorithm>
#include <limits>

#include "farlio/pipeline/cpu_scan_backend.hpp"
#ifdef FARLIO_WITH_CUDA
#include "farlio/cuda/cuda_scan_backend.hpp"
#endif

namespace farlio::pipeline {
namespace {
/// Voxels the CPU frame map preallocates (a scan fills ~1-2k; the pool doubles as needed).
constexpr std::int64_t kFrameMapInitialVoxels = 1024;
}  // namespace

VoxelMapConfig frame_map_config(const Config& c) {
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

std::unique_ptr<ScanBackend> make_scan_backend(const Config& config, std::string* message) {
  if (resolve_device(config.device, message) == Device::Cuda) {
#ifdef FARLIO_WITH_CUDA
    return cuda::make_cuda_scan_backend(config);
#endif
  }
  return std::make_unique<CpuScanBackend>(config);
}

}  // namespace farlio::pipeline
