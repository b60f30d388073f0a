#pragma once
// Error checking of CUDA runtime calls: every call goes through FARLIO_CUDA_CHECK, which throws
// farlio::DeviceError naming the call, its file:line and the CUDA error. Kernel launches are
// checked with FARLIO_CUDA_CHECK(cudaGetLastError()) right after the launch.
#include <cuda_runtime_api.h>

#include <string>

#include "farlio/core/error.hpp"

namespace farlio::cuda {

inline void check_call(cudaError_t status, const char* call, const char* file, int line) {
  if (status == cudaSuccess) return;
  throw DeviceError(std::string(call) + " failed at " + file + ":" + std::to_string(line) + ": " +
                    cudaGetErrorName(status) + " (" + cudaGetErrorString(status) + ")");
}

}  // namespace farlio::cuda

#define FARLIO_CUDA_CHECK(call) ::farlio::cuda::check_call((call), #call, __FILE__, __LINE__)
