#include <algorithm>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/device/device_select.cuh>
#include <limits>
#include <stdexcept>

#include "farlio/cuda/device_algorithms.hpp"

namespace farlio::cuda {
namespace {

constexpr int kKeyBits = 8 * sizeof(std::uint64_t);

std::size_t sort_bytes(std::size_t n) {
  std::size_t bytes = 0;
  FARLIO_CUDA_CHECK(
      cub::DeviceRadixSort::SortPairs(nullptr, bytes, static_cast<const std::uint64_t*>(nullptr),
                                      static_cast<std::uint64_t*>(nullptr), static_cast<const std::int32_t*>(nullptr),
                                      static_cast<std::int32_t*>(nullptr), static_cast<int>(n), 0, kKeyBits));
  return bytes;
}

std::size_t select_bytes(std::size_t n) {
  std::size_t bytes = 0;
  FARLIO_CUDA_CHECK(cub::DeviceSelect::Flagged(
      nullptr, bytes, static_cast<const std::int32_t*>(nullptr), static_cast<const std::uint8_t*>(nullptr),
      static_cast<std::int32_t*>(nullptr), static_cast<std::int32_t*>(nullptr), static_cast<int>(n)));
  return bytes;
}

std::size_t scan_bytes(std::size_t n) {
  std::size_t bytes = 0;
  FARLIO_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, bytes, static_cast<const std::int32_t*>(nullptr),
                                                  static_cast<std::int32_t*>(nullptr), static_cast<int>(n)));
  return bytes;
}

std::size_t temp_bytes_for(std::size_t max_items) {
  if (max_items >= static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw CapacityError("CUDA backend: " + std::to_string(max_items) + " items exceed the 2^31 limit of one sort");
  }
  return std::max({sort_bytes(max_items), select_bytes(max_items), scan_bytes(max_items), std::size_t{1}});
}

}  // namespace

DeviceAlgorithms::DeviceAlgorithms(std::size_t max_items, cudaStream_t stream)
    : max_items_(max_items), stream_(stream), temp_(temp_bytes_for(max_items), "temporary bytes of CUB") {}

// Every call passes the whole temporary buffer, sized at construction for the largest input of
// each algorithm (CUB takes more than it needs): asking CUB for the size first costs a second pass
// through its dispatch on the host, for each of a frame's dozen calls.
void DeviceAlgorithms::require(std::size_t n) const {
  if (n > max_items_) {
    throw CapacityError("CUDA backend: " + std::to_string(n) + " items exceed the " + std::to_string(max_items_) +
                        " the device buffers were sized for; raise cuda.max_scan_points");
  }
}

void DeviceAlgorithms::sort_pairs(const std::uint64_t* keys_in, std::uint64_t* keys_out, const std::int32_t* values_in,
                                  std::int32_t* values_out, std::size_t n, int key_bits) {
  if (n == 0) return;
  if (key_bits <= 0 || key_bits > kKeyBits) throw std::invalid_argument("sort_pairs: key_bits must be in [1, 64]");
  require(n);
  std::size_t bytes = temp_.bytes();
  FARLIO_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, keys_in, keys_out, values_in, values_out,
                                                    static_cast<int>(n), 0, key_bits, stream_));
}

void DeviceAlgorithms::select_flagged(const std::int32_t* in, const std::uint8_t* flags, std::int32_t* out,
                                      std::int32_t* count, std::size_t n) {
  if (n == 0) {
    FARLIO_CUDA_CHECK(cudaMemsetAsync(count, 0, sizeof(std::int32_t), stream_));
    return;
  }
  require(n);
  std::size_t bytes = temp_.bytes();
  FARLIO_CUDA_CHECK(
      cub::DeviceSelect::Flagged(temp_.data(), bytes, in, flags, out, count, static_cast<int>(n), stream_));
}

void DeviceAlgorithms::exclusive_sum(const std::int32_t* in, std::int32_t* out, std::size_t n) {
  if (n == 0) return;
  require(n);
  std::size_t bytes = temp_.bytes();
  FARLIO_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, in, out, static_cast<int>(n), stream_));
}

}  // namespace farlio::cuda
