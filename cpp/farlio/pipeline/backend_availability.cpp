#include "farlio/pipeline/backend_availability.hpp"

#include <stdexcept>

namespace farlio {

#ifdef FARLIO_WITH_CUDA
int cuda_device_count_impl();  // cpp/farlio/cuda/device_query.cu
bool cuda_compiled() { return true; }
int cuda_device_count() { return cuda_device_count_impl(); }
#else
bool cuda_compiled() { return false; }
int cuda_device_count() { return 0; }
#endif

Device resolve_device(Device requested, std::string* message) {
  if (requested == Device::Cpu) return Device::Cpu;
  const bool built = cuda_compiled();
  const int n = built ? cuda_device_count() : 0;
  if (n > 0) return Device::Cuda;
  const std::string why = built ? "no CUDA device was found" : "this build has no CUDA backend";
  if (requested == Device::Cuda)
    throw std::runtime_error("device cuda was requested but " + why + " (use --device auto or cpu)");
  if (message) *message = "device auto: " + why + "; running on the CPU";
  return Device::Cpu;
}

}  // namespace farlio
