#pragma once
// The CUB device-wide algorithms the backend needs (radix sort of key/index pairs, stream
// compaction, exclusive prefix sum) over one temporary buffer sized once for the largest input
// of each.
// Plain C++ header; the calls are in device_algorithms.cu.
#include <cuda_runtime_api.h>

#include <cstddef>
#include <cstdint>

#include "farlio/cuda/device_buffer.hpp"

namespace farlio::cuda {

class DeviceAlgorithms {
 public:
  /// Temporary storage for inputs of up to max_items items (< 2^31).
  DeviceAlgorithms(std::size_t max_items, cudaStream_t stream);

  /// Sorts (key, value) pairs by key, stably: with values 0..n-1 the order is (key, index). Only
  /// the low key_bits bits of the keys are compared (one radix pass per 8 bits or so).
  void sort_pairs(const std::uint64_t* keys_in, std::uint64_t* keys_out, const std::int32_t* values_in,
                  std::int32_t* values_out, std::size_t n, int key_bits = 64);
  /// out[0, count) = the in[i] whose flags[i] != 0, in order; *count (device memory) receives the
  /// count. No wait: the caller reads the count back with its other results.
  void select_flagged(const std::int32_t* in, const std::uint8_t* flags, std::int32_t* out, std::int32_t* count,
                      std::size_t n);
  /// out[i] = in[0] + ... + in[i - 1], out[0] = 0.
  void exclusive_sum(const std::int32_t* in, std::int32_t* out, std::size_t n);

  [[nodiscard]] std::size_t memory_bytes() const { return temp_.bytes(); }

 private:
  void require(std::size_t n) const;

  std::size_t max_items_;
  cudaStream_t stream_;
  DeviceBuffer<unsigned char> temp_;
};

}  // namespace farlio::cuda
