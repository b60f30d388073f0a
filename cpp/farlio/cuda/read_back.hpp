#pragma once
// Small device results (counts, sums, flags) copied into pinned host memory on one stream, so
// that all the results a stage needs cost the host one wait: post() queues a copy and says where
// it lands, wait() synchronises the stream once, value() reads the copy. Plain C++ header.
#include <cuda_runtime_api.h>

#include <cstddef>
#include <type_traits>

#include "farlio/cuda/cuda_check.hpp"

namespace farlio::cuda {

/// Where a posted value lands in a ReadBack's host memory.
template <typename T>
struct ReadSlot {
  std::size_t offset = 0;
};

class ReadBack {
 public:
  /// Pinned bytes held: a stage posts a few hundred.
  static constexpr std::size_t kBytes = 4096;

  explicit ReadBack(cudaStream_t stream);
  ~ReadBack();
  ReadBack(const ReadBack&) = delete;
  ReadBack& operator=(const ReadBack&) = delete;

  /// Starts a new set of copies (the values of the previous set are no longer read).
  void clear() { used_ = 0; }
  /// Queues the copy of n device values of type T; they can be read after wait().
  template <typename T>
  ReadSlot<T> post(const T* device, std::size_t n = 1) {
    static_assert(std::is_trivially_copyable_v<T>, "read-back values are copied bytes");
    const std::size_t offset = reserve(n * sizeof(T), alignof(T));
    if (n > 0)
      FARLIO_CUDA_CHECK(cudaMemcpyAsync(host_ + offset, device, n * sizeof(T), cudaMemcpyDeviceToHost, stream_));
    return {offset};
  }
  /// Waits for every copy queued on the stream (one synchronisation).
  void wait() const;
  /// The i-th value posted at `slot` (after wait()).
  template <typename T>
  [[nodiscard]] T value(ReadSlot<T> slot, std::size_t i = 0) const {
    T v;
    copy_out(&v, slot.offset + i * sizeof(T), sizeof(T));
    return v;
  }

 private:
  std::size_t reserve(std::size_t bytes, std::size_t alignment);
  void copy_out(void* out, std::size_t offset, std::size_t bytes) const;

  cudaStream_t stream_;
  unsigned char* host_ = nullptr;
  std::size_t used_ = 0;
};

}  // namespace farlio::cuda
