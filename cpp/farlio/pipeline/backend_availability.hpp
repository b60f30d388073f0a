#pragma once
// What the build and the machine offer the scan pipeline: whether the CUDA backend is compiled in,
// how many CUDA devices are usable, and the device a request for one resolves to. Part of
// farlio_pipeline, which links farlio_cuda where CUDA is built: farlio_core stays free of it.
#include <string>

#include "farlio/core/device.hpp"

namespace farlio {

/// True if this build contains the CUDA backend.
bool cuda_compiled();
/// Number of usable CUDA devices (0 without the backend, a driver or a GPU).
int cuda_device_count();
/// Resolves Auto to Cpu or Cuda; `message` explains a fallback. Throws if Cuda is asked for
/// and cannot be had.
Device resolve_device(Device requested, std::string* message = nullptr);

}  // namespace farlio
