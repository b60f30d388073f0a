#pragma once
// The few atomic operations the shared kernels need, on plain memory: std::atomic_ref on the
// host, the CUDA intrinsics on the device. Data structures stay flat arrays either way.
#include <atomic>
#include <cstdint>

#include "farlio/exec/hd.hpp"

namespace farlio::exec {

/// Compare-and-swap; returns the value that was at *addr (== expected on success).
FARLIO_HD inline std::uint64_t atomic_cas(std::uint64_t* addr, std::uint64_t expected, std::uint64_t desired) {
#ifdef FARLIO_ON_DEVICE
  return atomicCAS(reinterpret_cast<unsigned long long*>(addr), static_cast<unsigned long long>(expected),
                   static_cast<unsigned long long>(desired));
#else
  std::atomic_ref<std::uint64_t>(*addr).compare_exchange_strong(expected, desired, std::memory_order_acq_rel);
  return expected;
#endif
}

/// Fetch-and-add; returns the previous value.
FARLIO_HD inline std::int32_t atomic_add(std::int32_t* addr, std::int32_t v) {
#ifdef FARLIO_ON_DEVICE
  return atomicAdd(addr, v);
#else
  return std::atomic_ref<std::int32_t>(*addr).fetch_add(v, std::memory_order_acq_rel);
#endif
}

/// Relaxed-enough load for reading a slot another thread may publish.
FARLIO_HD inline std::uint64_t atomic_load(const std::uint64_t* addr) {
#ifdef FARLIO_ON_DEVICE
  return *reinterpret_cast<const volatile unsigned long long*>(addr);
#else
  return std::atomic_ref<const std::uint64_t>(*addr).load(std::memory_order_acquire);
#endif
}

}  // namespace farlio::exec
