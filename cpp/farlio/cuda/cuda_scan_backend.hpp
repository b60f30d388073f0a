#pragma once
// The scan pipeline's stages on the GPU (docs/cuda.md): the scan, the frame, the frame map, the
// source cloud and the submap live in device buffers allocated once from config.cuda; the
// per-point and per-voxel bodies are the shared FARLIO_HD functions.
#include <memory>

#include "farlio/core/config.hpp"
#include "farlio/pipeline/scan_backend.hpp"

namespace farlio::cuda {

/// Throws DeviceError when the CUDA runtime fails (no device, out of memory), CapacityError or
/// std::invalid_argument when config.cuda cannot make the buffers.
std::unique_ptr<pipeline::ScanBackend> make_cuda_scan_backend(const Config& config);

}  // namespace farlio::cuda
