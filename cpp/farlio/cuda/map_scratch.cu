#include <utility>

#include "farlio/cuda/cuda_executor.cuh"
#include "farlio/cuda/map_scratch.hpp"

namespace farlio::cuda {
namespace {

// (a free function: a constructor cannot enclose a __device__ lambda)
void fill_iota(CudaExecutor& executor, std::int32_t* out, std::size_t n) {
  executor.for_each(n, [=] __device__(std::size_t i) { out[i] = static_cast<std::int32_t>(i); });
}

}  // namespace

MapScratch::MapScratch(std::size_t n, CudaExecutor& executor)
    : items(n),
      keys(n, "keys"),
      sorted_keys(n, "keys"),
      short_keys(n, "keys"),
      iota(n, "keys"),
      sorted_order(n, "keys"),
      sorted_points(n, "keys"),
      flags(n, "keys"),
      group_start(n, "keys"),
      group_voxel(n, "keys"),
      missing(n, "keys"),
      rank(n, "keys"),
      first_new(n, "keys"),
      group_stats(n, "keys"),
      scalars(kScalarCount, "scalars") {
  fill_iota(executor, iota.data(), n);
  // every scalar defined from the start: sort_into_groups copies them back together
  FARLIO_CUDA_CHECK(cudaMemsetAsync(scalars.data(), 0, scalars.bytes(), executor.stream()));
}

std::size_t MapScratch::memory_bytes() const {
  return keys.bytes() + sorted_keys.bytes() + short_keys.bytes() + iota.bytes() + sorted_order.bytes() +
         sorted_points.bytes() + flags.bytes() + group_start.bytes() + group_voxel.bytes() + missing.bytes() +
         rank.bytes() + first_new.bytes() + group_stats.bytes() + scalars.bytes();
}

namespace {

/// Sorts the keys (short or full) and flags each group's first sorted key; the sorted full keys
/// end in s.sorted_keys. Queued, no wait.
void sort_and_flag(MapScratch& s, CudaExecutor& ex, DeviceAlgorithms& alg, std::size_t n,
                   const map::KeyWindow& window) {
  std::int32_t* scalars = s.scalars.data();
  const bool short_sort = window.usable();
  if (short_sort) {
    // the keys' short form in the window: the same order in fewer radix passes
    FARLIO_CUDA_CHECK(cudaMemsetAsync(scalars + kScalarOutsideWindow, 0, sizeof(std::int32_t), ex.stream()));
    const std::uint64_t* full = s.keys.data();
    std::uint64_t* shorter = s.short_keys.data();
    ex.for_each(n, [=] __device__(std::size_t i) {
      bool outside = false;
      shorter[i] = window.shorten(full[i], &outside);
      if (outside) scalars[kScalarOutsideWindow] = 1;  // any writer: the same value
    });
    alg.sort_pairs(s.short_keys.data(), s.sorted_keys.data(), s.iota.data(), s.sorted_order.data(), n,
                   window.total_bits());
  } else {
    alg.sort_pairs(s.keys.data(), s.sorted_keys.data(), s.iota.data(), s.sorted_order.data(), n);
  }
  const std::uint64_t* keys = s.sorted_keys.data();
  // the sorted short keys expand into short_keys, which then takes the name sorted_keys
  std::uint64_t* expanded = short_sort ? s.short_keys.data() : nullptr;
  std::uint8_t* flags = s.flags.data();
  const std::uint64_t empty_key = short_sort ? window.empty_short_key() : map::kEmptyKey;
  ex.for_each(n, [=] __device__(std::size_t i) {
    const std::uint64_t k = keys[i];
    const bool empty = k == empty_key;
    flags[i] = !empty && (i == 0 || k != keys[i - 1]);
    // exactly one thread writes where the valid keys end (empty keys sort last)
    if (empty && (i == 0 || keys[i - 1] != empty_key)) scalars[kScalarFirstEmpty] = static_cast<std::int32_t>(i);
    if (!empty && i == n - 1) scalars[kScalarFirstEmpty] = static_cast<std::int32_t>(n);
    if (expanded) expanded[i] = window.expand(k);
  });
  if (short_sort) std::swap(s.sorted_keys, s.short_keys);
}

}  // namespace

SortedGroups sort_into_groups(MapScratch& s, CudaExecutor& ex, DeviceAlgorithms& alg, std::size_t n,
                              const map::KeyWindow& window, const AfterSort& after_sort) {
  if (n == 0) return {};
  s.keys.require(n + 1, "cuda.max_scan_points");  // + 1: the end of the last group
  sort_and_flag(s, ex, alg, n, window);
  std::int32_t* scalars = s.scalars.data();
  alg.select_flagged(s.iota.data(), s.flags.data(), s.group_start.data(), scalars + kScalarGroups, n);
  std::int32_t* starts = s.group_start.data();
  ex.for_each(1, [=] __device__(std::size_t) { starts[scalars[kScalarGroups]] = scalars[kScalarFirstEmpty]; });
  ReadBack& rb = ex.read_back();
  rb.clear();
  if (after_sort) after_sort(rb);
  const ReadSlot<std::int32_t> found = rb.post(scalars, kScalarCount);
  rb.wait();
  if (window.usable() && rb.value(found, kScalarOutsideWindow) != 0) {
    return sort_into_groups(s, ex, alg, n, map::KeyWindow{}, after_sort);
  }
  return {static_cast<std::size_t>(rb.value(found, kScalarGroups)),
          static_cast<std::size_t>(rb.value(found, kScalarFirstEmpty))};
}

}  // namespace farlio::cuda
