#include "farlio/cuda/staged_upload.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/cuda/cuda_check.hpp"
#include "farlio/exec/cpu_executor.hpp"

namespace farlio::cuda {
namespace {

/// Bytes each host task copies: large enough that a task costs more than its scheduling.
constexpr std::size_t kCopyBlockBytes = std::size_t{64} << 10;

}  // namespace

StagedUpload::StagedUpload(std::size_t capacity_bytes, int threads)
    : capacity_(capacity_bytes),
      copier_(std::make_unique<exec::CpuExecutor>(threads > 0 ? std::min(threads, kMaxCopyThreads) : kMaxCopyThreads)) {
  FARLIO_CUDA_CHECK(cudaMallocHost(reinterpret_cast<void**>(&pinned_), std::max<std::size_t>(capacity_, 1)));
  FARLIO_CUDA_CHECK(cudaEventCreateWithFlags(&taken_, cudaEventDisableTiming));
  copier_->warm_up();
}

StagedUpload::~StagedUpload() {
  if (taken_) cudaEventDestroy(taken_);  // no throw from a destructor
  if (pinned_) cudaFreeHost(pinned_);
}

void StagedUpload::begin_frame() {
  FARLIO_CUDA_CHECK(cudaEventSynchronize(taken_));
  used_ = 0;
}

void StagedUpload::upload(const void* host, void* device, std::size_t bytes, cudaStream_t stream) {
  if (bytes == 0) return;
  if (used_ + bytes > capacity_) {
    throw CapacityError("CUDA backend: an upload of " + std::to_string(used_ + bytes) +
                        " bytes exceeds the page-locked buffer of " + std::to_string(capacity_) +
                        "; raise cuda.max_scan_points");
  }
  unsigned char* staged = pinned_ + used_;
  const auto* from = static_cast<const unsigned char*>(host);
  const std::size_t blocks = (bytes + kCopyBlockBytes - 1) / kCopyBlockBytes;
  copier_->for_each(
      blocks,
      [&](std::size_t b) {
        const std::size_t first = b * kCopyBlockBytes;
        std::memcpy(staged + first, from + first, std::min(kCopyBlockBytes, bytes - first));
      },
      1);
  FARLIO_CUDA_CHECK(cudaMemcpyAsync(device, staged, bytes, cudaMemcpyHostToDevice, stream));
  FARLIO_CUDA_CHECK(cudaEventRecord(taken_, stream));
  used_ += bytes;
}

}  // namespace farlio::cuda
