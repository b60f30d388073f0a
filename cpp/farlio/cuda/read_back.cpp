#include "farlio/cuda/read_back.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

namespace farlio::cuda {

ReadBack::ReadBack(cudaStream_t stream) : stream_(stream) {
  FARLIO_CUDA_CHECK(cudaMallocHost(reinterpret_cast<void**>(&host_), kBytes));
}

ReadBack::~ReadBack() {
  if (host_) cudaFreeHost(host_);  // no throw from a destructor
}

void ReadBack::wait() const { FARLIO_CUDA_CHECK(cudaStreamSynchronize(stream_)); }

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
