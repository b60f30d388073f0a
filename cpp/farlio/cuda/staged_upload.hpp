#pragma once
// Host-to-device copies through page-locked memory. A copy from pageable memory goes through the
// driver's own staging, one thread at a time: a cold 2 MB scan took ~0.25 ms of a 1 ms GPU frame
// on an H100 host. Here the host copies the bytes into a page-locked buffer on several threads
// (at the memory's speed) and the copy engine takes them from there at the bus's speed, while
// the host copies the next array. Plain C++ header (the threads are TBB's, in the .cpp).
#include <cuda_runtime_api.h>

#include <cstddef>
#include <memory>

namespace farlio::exec {
class CpuExecutor;
}

namespace farlio::cuda {

class StagedUpload {
 public:
  /// Host threads of a copy at most: four reach a host's memory bandwidth for a 2-4 MB copy, and
  /// each thread more is one more that a busy host can preempt in the middle of a frame.
  static constexpr int kMaxCopyThreads = 4;

  /// `capacity_bytes`: what one frame uploads at most; `threads`: host threads of the copies
  /// into page-locked memory (0: kMaxCopyThreads; never more).
  StagedUpload(std::size_t capacity_bytes, int threads);
  ~StagedUpload();
  StagedUpload(const StagedUpload&) = delete;
  StagedUpload& operator=(const StagedUpload&) = delete;

  /// Starts a frame: waits until the copy engine has taken the last frame's bytes, then reuses
  /// the buffer from its start.
  void begin_frame();
  /// Queues the copy of `bytes` host bytes to `device` on `stream`; returns once the host's part
  /// is done (the host memory can then change). Throws CapacityError beyond the capacity.
  void upload(const void* host, void* device, std::size_t bytes, cudaStream_t stream);
  [[nodiscard]] std::size_t memory_bytes() const { return capacity_; }

 private:
  unsigned char* pinned_ = nullptr;
  std::size_t capacity_ = 0;
  std::size_t used_ = 0;
  cudaEvent_t taken_ = nullptr;  // after the last copy out of the buffer
  std::unique_ptr<exec::CpuExecutor> copier_;
};

}  // namespace farlio::cuda
