#pragma once
// Small device results (counts, sums, flags) brought to the host on one stream, so that all the
// results a stage needs cost the host one wait: post() says where a value will land, wait()
// launches one kernel that writes every posted value into page-locked host memory (mapped into
// the device's address space) and synchronises the stream once, value() reads it. One launch a
// wait, where a copy per value would queue one copy-engine operation each. Plain C++ header.
#include <cuda_runtime_api.h>

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "farlio/cuda/cuda_check.hpp"

namespace farlio::cuda {

/// Where a posted value lands in a ReadBack's host memory.
template <typename T>
struct ReadSlot {
  std::size_t offset = 0;
};

/// The values a ReadBack brings back at its next wait: where each is on the device and where it
/// lands in the host memory (the gather kernel's argument).
struct ReadBackEntries {
  static constexpr int kMax = 16;
  const void* from[kMax];
  std::uint32_t offset[kMax];
  std::uint32_t bytes[kMax];
  int count = 0;
};

class ReadBack {
 public:
  /// Pinned bytes held: a stage posts a few hundred.
  static constexpr std::size_t kBytes = 4096;

  explicit ReadBack(cudaStream_t stream);
  ~ReadBack();
  ReadBack(const ReadBack&) = delete;
  ReadBack& operator=(const ReadBack&) = delete;

  /// Starts a new set of values (the previous set is no longer read, nor brought back).
  void clear() {
    used_ = 0;
    entries_.count = 0;
  }
  /// Device values posted between two waits at most.
  static constexpr int kMaxEntries = ReadBackEntries::kMax;

  /// Notes n device values of type T to bring back at the next wait(); they can be read after it.
  template <typename T>
  ReadSlot<T> post(const T* device, std::size_t n = 1) {
    static_assert(std::is_trivially_copyable_v<T>, "read-back values are copied bytes");
    const std::size_t offset = reserve(n * sizeof(T), alignof(T));
    if (n > 0) note(device, offset, n * sizeof(T));
    return {offset};
  }
  /// Brings every value posted since the last wait to the host (one launch, one synchronisation).
  void wait();
  /// The i-th value posted at `slot` (after wait()).
  template <typename T>
  [[nodiscard]] T value(ReadSlot<T> slot, std::size_t i = 0) const {
    T v;
    copy_out(&v, slot.offset + i * sizeof(T), sizeof(T));
    return v;
  }

 private:
  std::size_t reserve(std::size_t bytes, std::size_t alignment);
  void note(const void* device, std::size_t offset, std::size_t bytes);
  void copy_out(void* out, std::size_t offset, std::size_t bytes) const;

  cudaStream_t stream_;
  unsigned char* host_ = nullptr;    // page-locked, mapped
  unsigned char* mapped_ = nullptr;  // host_ as the device addresses it
  std::size_t used_ = 0;
  ReadBackEntries entries_;
};

}  // namespace farlio::cuda
