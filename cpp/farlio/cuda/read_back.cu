#include <cstring>
#include <stdexcept>
#include <string>

#include "farlio/cuda/read_back.hpp"

namespace farlio::cuda {
namespace {

/// Threads of the one block that copies the posted values (a stage posts a few hundred bytes).
constexpr unsigned kGatherThreads = 256;

/// Every posted value into the mapped host memory, byte by byte (a warp's neighbouring bytes go
/// out as one write).
__global__ void __launch_bounds__(kGatherThreads) gather_kernel(ReadBackEntries e, unsigned char* host) {
  for (int k = 0; k < e.count; ++k) {
    const auto* from = static_cast<const unsigned char*>(e.from[k]);
    for (std::uint32_t b = threadIdx.x; b < e.bytes[k]; b += blockDim.x) host[e.offset[k] + b] = from[b];
  }
  // no system fence: the host reads the values after synchronising the stream, which orders them
}

}  // namespace

ReadBack::ReadBack(cudaStream_t stream) : stream_(stream) {
  FARLIO_CUDA_CHECK(cudaHostAlloc(reinterpret_cast<void**>(&host_), kBytes, cudaHostAllocMapped));
  FARLIO_CUDA_CHECK(cudaHostGetDevicePointer(reinterpret_cast<void**>(&mapped_), host_, 0));
}

ReadBack::~ReadBack() {
  if (host_) cudaFreeHost(host_);  // no throw from a destructor
}

void ReadBack::note(const void* device, std::size_t offset, std::size_t bytes) {
  if (entries_.count == kMaxEntries) {
    throw std::logic_error("ReadBack: more than " + std::to_string(kMaxEntries) + " values posted before a wait");
  }
  entries_.from[entries_.count] = device;
  entries_.offset[entries_.count] = static_cast<std::uint32_t>(offset);
  entries_.bytes[entries_.count] = static_cast<std::uint32_t>(bytes);
  ++entries_.count;
}

void ReadBack::wait() {
  if (entries_.count > 0) {
    gather_kernel<<<1, kGatherThreads, 0, stream_>>>(entries_, mapped_);
    entries_.count = 0;
    FARLIO_CUDA_CHECK(cudaGetLastError());
  }
  FARLIO_CUDA_CHECK(cudaStreamSynchronize(stream_));
}

std::size_t ReadBack::reserve(std::size_t bytes, std::size_t alignment) {
  const std::size_t offset = (used_ + alignment - 1) / alignment * alignment;
  if (offset + bytes > kBytes) {
    throw std::logic_error("ReadBack: " + std::to_string(offset + bytes) + " bytes posted exceed its " +
                           std::to_string(kBytes));
  }
  used_ = offset + bytes;
  return offset;
}

void ReadBack::copy_out(void* out, std::size_t offset, std::size_t bytes) const {
  if (offset + bytes > used_) throw std::logic_error("ReadBack: a value read beyond what was posted");
  std::memcpy(out, host_ + offset, bytes);
}

}  // namespace farlio::cuda
