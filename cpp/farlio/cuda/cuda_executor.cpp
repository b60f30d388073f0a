#include "farlio/cuda/cuda_executor.hpp"

namespace farlio::cuda {

CudaExecutor::CudaExecutor() : partials_((kMaxReduceBlocks + 1) * kMaxReduceValueBytes, "reduction partial bytes") {
  int device = 0, sms = 0;
  FARLIO_CUDA_CHECK(cudaGetDevice(&device));
  FARLIO_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
  max_blocks_ = static_cast<unsigned>(sms) * kBlocksPerSm;
  FARLIO_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));
}

CudaExecutor::~CudaExecutor() {
  if (stream_) cudaStreamDestroy(stream_);  // no throw from a destructor
}

void CudaExecutor::synchronize() const { FARLIO_CUDA_CHECK(cudaStreamSynchronize(stream_)); }

}  // namespace farlio::cuda
