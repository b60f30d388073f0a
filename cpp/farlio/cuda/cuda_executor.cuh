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

/// Pass 1: each block reduces a grid-stride share of [0, n) into partials[blockIdx.x].
template <typename T, typename Map, typename Combine>
__global__ void __launch_bounds__(CudaExecutor::kReduceThreads)
    reduce_blocks_kernel(std::size_t n, T identity, Map map, Combine combine, T* partials) {
  using BlockReduce = cub::BlockReduce<T, CudaExecutor::kReduceThreads>;
  __shared__ typename BlockReduce::TempStorage temp;
  T acc = identity;
  const std::size_t stride = static_cast<std::size_t>(gridDim.x) * blockDim.x;
  for (std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) {
    acc = combine(acc, map(i));
  }
  const T block = BlockReduce(temp).Reduce(acc, combine);
  if (threadIdx.x == 0) partials[blockIdx.x] = block;
}

/// Pass 2: one block reduces the partials into *out.
template <typename T, typename Combine>
__global__ void __launch_bounds__(CudaExecutor::kReduceThreads)
    reduce_partials_kernel(unsigned count, T identity, Combine combine, const T* partials, T* out) {
  using BlockReduce = cub::BlockReduce<T, CudaExecutor::kReduceThreads>;
  __shared__ typename BlockReduce::TempStorage temp;
  T acc = identity;
  for (unsigned i = threadIdx.x; i < count; i += blockDim.x) acc = combine(acc, partials[i]);
  const T total = BlockReduce(temp).Reduce(acc, combine);
  if (threadIdx.x == 0) *out = total;
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
T CudaExecutor::reduce(std::size_t n, const T& identity, const Map& map, const Combine& combine) {
  static_assert(std::is_trivially_copyable_v<T>, "reduce values are copied between host and device");
  static_assert(sizeof(T) <= kMaxReduceValueBytes, "raise CudaExecutor::kMaxReduceValueBytes");
  if (n == 0) return identity;
  T* partials = reinterpret_cast<T*>(partials_.data());
  T* out = partials + kMaxReduceBlocks;
  const unsigned blocks = detail::blocks_for(n, kReduceThreads, kMaxReduceBlocks);  // depends on n only
  detail::reduce_blocks_kernel<<<blocks, kReduceThreads, 0, stream_>>>(n, identity, map, combine, partials);
  FARLIO_CUDA_CHECK(cudaGetLastError());
  detail::reduce_partials_kernel<<<1, kReduceThreads, 0, stream_>>>(blocks, identity, combine, partials, out);
  FARLIO_CUDA_CHECK(cudaGetLastError());
  T result;
  FARLIO_CUDA_CHECK(cudaMemcpyAsync(&result, out, sizeof(T), cudaMemcpyDeviceToHost, stream_));
  synchronize();
  return result;
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
