#pragma once
// The CUDA executor: the GPU counterpart of exec::CpuExecutor. for_each(n, body) launches a
// grid-stride kernel that calls body(i) for every i in [0, n); reduce(n, identity, map, combine)
// reduces map(i) with CUB block reductions (deterministic for a given n: the grid depends on n
// only). Both are defined in cuda_executor.cuh (nvcc only); this header is plain C++ so host
// code can hold an executor. One stream per executor, no process-wide state.
#include <cuda_runtime_api.h>

#include <cstddef>

#include "farlio/cuda/device_buffer.hpp"

namespace farlio::cuda {

class CudaExecutor {
 public:
  /// Threads per block of for_each and reduce.
  static constexpr unsigned kForEachThreads = 256;
  static constexpr unsigned kReduceThreads = 128;
  /// Blocks of the first reduction pass at most (their partials are reduced by one block).
  static constexpr unsigned kMaxReduceBlocks = 512;
  /// Largest value type reduce accepts (partials are preallocated for it).
  static constexpr std::size_t kMaxReduceValueBytes = 256;
  /// for_each grids are capped at this many blocks per SM (grid-stride beyond).
  static constexpr unsigned kBlocksPerSm = 8;

  /// Uses the current device; creates the stream and the reduction buffers.
  CudaExecutor();
  ~CudaExecutor();
  CudaExecutor(const CudaExecutor&) = delete;
  CudaExecutor& operator=(const CudaExecutor&) = delete;

  [[nodiscard]] cudaStream_t stream() const { return stream_; }
  void synchronize() const;
  [[nodiscard]] std::size_t memory_bytes() const { return partials_.bytes(); }

  template <typename Body>
  void for_each(std::size_t n, const Body& body);
  template <typename T, typename Map, typename Combine>
  T reduce(std::size_t n, const T& identity, const Map& map, const Combine& combine);

 private:
  cudaStream_t stream_ = nullptr;
  unsigned max_blocks_ = 0;
  DeviceBuffer<unsigned char> partials_;  // kMaxReduceBlocks partials, then the result
};

}  // namespace farlio::cuda
