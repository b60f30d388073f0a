#include "farlio/cuda/cuda_executor.hpp"

namespace farlio::cuda {

namespace {

cudaStream_t new_stream() {
  cudaStream_t stream = nullptr;
  FARLIO_CUDA_CHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
  return stream;
}

}  // namespace

CudaExecutor::CudaExecutor()
    : stream_(new_stream()),
      partials_((kMaxReduceBlocks + 1) * kMaxReduceValueBytes, "reduction partial bytes"),
      blocks_done_(1, "reduction counters"),
      read_back_(stream_),
      reduce_result_(stream_) {
  int device = 0, sms = 0;
  FARLIO_CUDA_CHECK(cudaGetDevice(&device));
  FARLIO_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
  max_blocks_ = static_cast<unsigned>(sms) * kBlocksPerSm;
  // the last block of each reduction sets it back to 0
  FARLIO_CUDA_CHECK(cudaMemsetAsync(blocks_done_.data(), 0, blocks_done_.bytes(), stream_));
}

CudaExecutor::~CudaExecutor() {
  if (stream_) cudaStreamDestroy(stream_);  // no throw from a destructor
}

void CudaExecutor::synchronize() const { FARLIO_CUDA_CHECK(cudaStreamSynchronize(stream_)); }

}  // namespace farlio::cuda
