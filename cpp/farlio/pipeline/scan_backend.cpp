#include "farlio/pipeline/scan_backend.hpp"

#include <limits>

#include "farlio/pipeline/cpu_scan_backend.hpp"
#ifdef FARLIO_WITH_CUDA
#include "farlio/cuda/cuda_scan_backend.hpp"
#endif

namespace farlio::pipeline {

VoxelMapConfig frame_map_config(const Config& c) {
  VoxelMapConfig f = c.map;
  // the frame map keeps the submap's spacing (the scan is downsampled to it) with a lower cap
  f.point_spacing_m = map::point_spacing_m(c.map);
  f.max_points_per_voxel = c.density.frame_map_max_points_per_voxel;
  f.refresh_covariances = false;
  f.removal_radius_m = std::numeric_limits<double>::infinity();
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
