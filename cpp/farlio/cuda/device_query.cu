// The CUDA runtime query behind farlio::cuda_device_count (cpp/farlio/pipeline/backend_availability.hpp).
#include <cuda_runtime.h>

namespace farlio {

int cuda_device_count_impl() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no driver" error
    return 0;
  }
  return n;
}

}  // namespace farlio
