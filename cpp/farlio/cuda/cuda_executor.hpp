#pragma once
// The CUDA executor: the GPU counterpart of exec::CpuExecutor. for_each(n, body) launches a
// grid-stride kernel that calls body(i) for every i in [0, n); reduce_into(n, identity, map,
// combine, out) reduces map(i) into a device value in one launch (CUB block reductions, the last
// block to finish reduces the blocks' partials: deterministic for a given n, the grid depends on
// n only), and reduce() also reads it back. They are defined in cuda_executor.cuh (nvcc only);
// this header is plain C++ so host code can hold an executor. One stream per executor, no
// process-wide state.
#include <cuda_runtime_api.h>

#include <cstddef>

#include "farlio/cuda/device_buffer.hpp"
#include "farlio/cuda/read_back.hpp"

namespace farlio::cuda {

class CudaExecutor {
 public:
  /// Threads per block of for_each and reduce.
  static constexpr unsigned kForEachThreads = 256;
  static constexpr unsigned kReduceThreads = 128;
  /// Blocks of a reduction at most (the last to finish reduces their partials).
  static constexpr unsigned kMaxReduceBlocks = 512;
  /// Largest value type reduce accepts (partials are preallocated for it).
  static constexpr std::size_t kMaxReduceValueBytes = 256;
  /// for_each grids are capped at this many blocks per SM (grid-stride beyond).
  static constexpr unsigned kBlocksPerSm = 8;

  /// Uses the current device; creates the stream, the reduction buffers and the read-back.
  CudaExecutor();
  ~CudaExecutor();
  CudaExecutor(const CudaExecutor&) = delete;
  CudaExecutor& operator=(const CudaExecutor&) = delete;

  [[nodiscard]] cudaStream_t stream() const { return stream_; }
  void synchronize() const;
  [[nodiscard]] std::size_t memory_bytes() const { return partials_.bytes() + blocks_done_.bytes(); }
  /// The pinned host memory that a stage's device results are read back through (one wait).
  [[nodiscard]] ReadBack& read_back() { return read_back_; }

  template <typename Body>
  void for_each(std::size_t n, const Body& body);
  /// *out = the reduction of map(i) over [0, n) (identity when n is 0), on the stream, no wait.
  template <typename T, typename Map, typename Combine>
  void reduce_into(std::size_t n, const T& identity, const Map& map, const Combine& combine, T* out);
  /// The same reduction, read back (waits for it).
  template <typename T, typename Map, typename Combine>
  T reduce(std::size_t n, const T& identity, const Map& map, const Combine& combine);

 private:
  cudaStream_t stream_ = nullptr;
  unsigned max_blocks_ = 0;
  DeviceBuffer<unsigned char> partials_;  // kMaxReduceBlocks partials, then reduce()'s result
  DeviceBuffer<unsigned> blocks_done_;    // blocks of the running reduction that have finished
  ReadBack read_back_;
  ReadBack reduce_result_;  // reduce()'s own, so that it never clears a stage's read-back
};

}  // namespace farlio::cuda
