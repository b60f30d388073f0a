// The backend factory. It names the CUDA backend, so it lives in farlio_pipeline, the library
// linked above both farlio_core and farlio_cuda (cpp/CMakeLists.txt).
#include "farlio/pipeline/scan_backend.hpp"

#include "farlio/pipeline/backend_availability.hpp"
#include "farlio/pipeline/cpu_scan_backend.hpp"
#ifdef FARLIO_WITH_CUDA
#include "farlio/cuda/cuda_scan_backend.hpp"
#endif

namespace farlio::pipeline {

std::unique_ptr<ScanBackend> make_scan_backend(const Config& config, std::string* message) {
  if (resolve_device(config.device, message) == Device::Cuda) {
#ifdef FARLIO_WITH_CUDA
    return cuda::make_cuda_scan_backend(config);
#endif
  }
  return std::make_unique<CpuScanBackend>(config);
}

}  // namespace farlio::pipeline
