#pragma once
// The scan pipeline's stages on the GPU (docs/cuda.md): the scan, the frame, the frame map, the
// source cloud and the submap live in device buffers allocated once from config.cuda; the
// per-point and per-voxel bodies are the shared FARLIO_HD functions.
#include <memory>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/cuda/kernel_bandwidth.hpp"
#include "farlio/pipeline/scan_backend.hpp"

namespace farlio::cuda {

/// Throws DeviceError when the CUDA runtime fails (no device, out of memory), CapacityError or
/// std::invalid_argument when config.cuda cannot make the buffers.
std::unique_ptr<pipeline::ScanBackend> make_cuda_scan_backend(const Config& config);

/// The copy ceiling, the k-NN of the submap's points (the covariance search) and the GICP
/// reduction of the last frame's source at its pose, on a CUDA backend that has processed at
/// least one frame (allocates temporary buffers: for bench/gpu_pipeline). Throws
/// std::invalid_argument when `backend` is not the CUDA backend.
std::vector<BandwidthSample> measure_kernel_bandwidth(pipeline::ScanBackend& backend, int repeats);

}  // namespace farlio::cuda
