#pragma once
// The kernels behind CudaExecutor::for_each and ::reduce (nvcc only). The bodies are the shared
// FARLIO_HD functions, called from __device__ lambdas (--extended-lambda).
#include <cub/block/block_reduce.cuh>
#include <type_traits>

#include "farlio/cuda/cuda_executor.hpp"

namespace farlio::cuda {
namespace detail {

template <typename Body>
__global__ void for_each_kernel(std::size_t n, Body body) {
  const std::size_t stride = static_cast<std::size_t>(gridDim.x) * blockDim.x;
  for (std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) body(i);
}

/// Each block reduces a grid-stride share of [0, n) into partials[blockIdx.x]; the last block to
/// finish reduces the partials, in block order, into *out and sets *blocks_done back to 0 for the
/// next launch. The partials are reduced in the same order whichever block finishes last, so the
/// result depends on n only.
template <typename T, typename Map, typename Combine>
__global__ void __launch_bounds__(CudaExecutor::kReduceThreads)
    reduce_kernel(std::size_t n, T identity, Map map, Combine combine, T* partials, unsigned* blocks_done, T* out) {
  using BlockReduce = cub::BlockReduce<T, CudaExecutor::kReduceThreads>;
  __shared__ typename BlockReduce::TempStorage temp;
  __shared__ bool last_block;
  T acc = identity;
  const std::size_t stride = static_cast<std::size_t>(gridDim.x) * blockDim.x;
  for (std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) {
    acc = combine(acc, map(i));
  }
  const T block = BlockReduce(temp).Reduce(acc, combine);
  if (threadIdx.x == 0) {
    partials[blockIdx.x] = block;
    __threadfence();  // the partial is visible to every block before the count says it is done
    last_block = atomicAdd(blocks_done, 1u) == gridDim.x - 1;
  }
  __syncthreads();
  if (!last_block) return;
  __threadfence();  // every other block's partial is read after its count
  T total = identity;
  for (unsigned i = threadIdx.x; i < gridDim.x; i += blockDim.x) total = combine(total, partials[i]);
  __syncthreads();  // temp is reused
  total = BlockReduce(temp).Reduce(total, combine);
  if (threadIdx.x == 0) {
    *out = total;
    *blocks_done = 0;
  }
}

inline unsigned blocks_for(std::size_t n, unsigned threads, unsigned max_blocks) {
  const std::size_t needed = (n + threads - 1) / threads;
  return static_cast<unsigned>(needed < max_blocks ? needed : max_blocks);
}

}  // namespace detail

template <typename Body>
void CudaExecutor::for_each(std::size_t n, const Body& body) {
  if (n == 0) return;
  detail::for_each_kernel<<<detail::blocks_for(n, kForEachThreads, max_blocks_), kForEachThreads, 0, stream_>>>(n,
                                                                                                                body);
  FARLIO_CUDA_CHECK(cudaGetLastError());
}

template <typename T, typename Map, typename Combine>
void CudaExecutor::reduce_into(std::size_t n, const T& identity, const Map& map, const Combine& combine, T* out) {
  static_assert(std::is_trivially_copyable_v<T>, "reduce values are copied between host and device");
  static_assert(sizeof(T) <= kMaxReduceValueBytes, "raise CudaExecutor::kMaxReduceValueBytes");
  // depends on n only; one block when n is 0, which writes the identity
  const unsigned blocks = n == 0 ? 1 : detail::blocks_for(n, kReduceThreads, kMaxReduceBlocks);
  detail::reduce_kernel<<<blocks, kReduceThreads, 0, stream_>>>(
      n, identity, map, combine, reinterpret_cast<T*>(partials_.data()), blocks_done_.data(), out);
  FARLIO_CUDA_CHECK(cudaGetLastError());
}

template <typename T, typename Map, typename Combine>
T CudaExecutor::reduce(std::size_t n, const T& identity, const Map& map, const Combine& combine) {
  if (n == 0) return identity;
  T* out = reinterpret_cast<T*>(partials_.data()) + kMaxReduceBlocks;
  reduce_into(n, identity, map, combine, out);
  reduce_result_.clear();
  const ReadSlot<T> slot = reduce_result_.post(out);
  reduce_result_.wait();
  return reduce_result_.value(slot);
}

/// The combine of sums over plain structs with operator+= (device and host).
struct Add {
  template <typename T>
  __host__ __device__ T operator()(T a, const T& b) const {
    a += b;
    return a;
  }
};

}  // namespace farlio::cuda
