#include "farlio/cuda/staged_upload.hpp"

#include <algorithm>
#include <cstring>
#include <span>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/cuda/cuda_check.hpp"
#include "farlio/exec/cpu_executor.hpp"

namespace farlio::cuda {
namespace {

/// Bytes each host task copies, then hands to the copy engine: large enough that a task costs
/// more than its scheduling and its cudaMemcpyAsync, small enough that the engine starts on the
/// first piece while the host threads still copy the others (a 2 MB scan is 8 pieces).
constexpr std::size_t kPieceBytes = std::size_t{256} << 10;

}  // namespace

/// A piece of a transfer: its host bytes, their place in the page-locked buffer, and on the device.
struct StagedUpload::Piece {
  const unsigned char* from;
  unsigned char* staged;
  unsigned char* to;
  std::size_t bytes;
};

StagedUpload::StagedUpload(std::size_t capacity_bytes, int threads)
    : capacity_(capacity_bytes),
      copier_(std::make_unique<exec::CpuExecutor>(threads > 0 ? std::min(threads, kMaxCopyThreads) : kMaxCopyThreads)) {
  FARLIO_CUDA_CHECK(cudaGetDevice(&device_));
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
  const Transfer one{host, device, bytes};
  upload(std::span<const Transfer>(&one, 1), stream);
}

void StagedUpload::upload(std::span<const Transfer> transfers, cudaStream_t stream) {
  // the pieces of all the transfers, in one list: the host threads share them out evenly
  std::size_t total = 0;
  for (const Transfer& t : transfers) total += t.bytes;
  if (total == 0) return;
  if (used_ + total > capacity_) {
    throw CapacityError("CUDA backend: an upload of " + std::to_string(used_ + total) +
                        " bytes exceeds the page-locked buffer of " + std::to_string(capacity_) +
                        "; raise cuda.max_scan_points");
  }
  pieces_.clear();
  for (const Transfer& t : transfers) {
    const auto* from = static_cast<const unsigned char*>(t.host);
    auto* to = static_cast<unsigned char*>(t.device);
    for (std::size_t first = 0; first < t.bytes; first += kPieceBytes) {
      pieces_.push_back({from + first, pinned_ + used_ + first, to + first, std::min(kPieceBytes, t.bytes - first)});
    }
    used_ += t.bytes;
  }
  const int device_id = device_;
  const Piece* pieces = pieces_.data();
  // each piece goes to the copy engine as soon as its host copy is done: the bus takes the first
  // pieces while the host threads copy the rest (pieces are disjoint: any order on the stream)
  copier_->for_each(
      pieces_.size(),
      [&](std::size_t i) {
        const Piece& p = pieces[i];
        std::memcpy(p.staged, p.from, p.bytes);
        FARLIO_CUDA_CHECK(cudaSetDevice(device_id));  // a pool thread's current device is its own
        FARLIO_CUDA_CHECK(cudaMemcpyAsync(p.to, p.staged, p.bytes, cudaMemcpyHostToDevice, stream));
      },
      1);
  FARLIO_CUDA_CHECK(cudaEventRecord(taken_, stream));
}

}  // namespace farlio::cuda
