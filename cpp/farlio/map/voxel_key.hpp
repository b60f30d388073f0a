#pragma once
// Integer voxel coordinates, their packed 64-bit key and the spatial hash (Teschner et al.,
// the hash named in the paper). Shared by the CPU and CUDA backends.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"

namespace farlio::map {

/// 21 bits per axis: +-2^20 voxels, i.e. +-4194 km at 4 m voxels.
inline constexpr int kKeyBitsPerAxis = 21;
inline constexpr std::int32_t kKeyAxisOffset = 1 << (kKeyBitsPerAxis - 1);
inline constexpr std::uint64_t kKeyAxisMask = (std::uint64_t{1} << kKeyBitsPerAxis) - 1;
/// Valid keys use 63 bits, so these two can never collide with one.
inline constexpr std::uint64_t kEmptyKey = ~std::uint64_t{0};
inline constexpr std::uint64_t kErasedKey = ~std::uint64_t{0} - 1;

using VoxelCoord = Eigen::Vector3i;

FARLIO_HD inline VoxelCoord voxel_of(const Eigen::Vector3f& p, float inv_voxel_size) {
  return {exec::floor_to_int(p.x() * inv_voxel_size), exec::floor_to_int(p.y() * inv_voxel_size),
          exec::floor_to_int(p.z() * inv_voxel_size)};
}

FARLIO_HD inline std::uint64_t pack_key(const VoxelCoord& c) {
  const auto axis = [](int v) { return static_cast<std::uint64_t>(v + kKeyAxisOffset) & kKeyAxisMask; };
  return axis(c.x()) | (axis(c.y()) << kKeyBitsPerAxis) | (axis(c.z()) << (2 * kKeyBitsPerAxis));
}

FARLIO_HD inline VoxelCoord unpack_key(std::uint64_t key) {
  const auto axis = [](std::uint64_t k) { return static_cast<int>(k & kKeyAxisMask) - kKeyAxisOffset; };
  return {axis(key), axis(key >> kKeyBitsPerAxis), axis(key >> (2 * kKeyBitsPerAxis))};
}

/// True if the point lies inside the representable key range.
FARLIO_HD inline bool in_key_range(const VoxelCoord& c) {
  const int lim = kKeyAxisOffset - 1;
  return c.x() > -lim && c.x() < lim && c.y() > -lim && c.y() < lim && c.z() > -lim && c.z() < lim;
}

/// Spatial hash of voxel coordinates (XOR of coordinates times large primes).
FARLIO_HD inline std::uint64_t spatial_hash(const VoxelCoord& c) {
  constexpr std::uint32_t kP1 = 73856093u, kP2 = 19349669u, kP3 = 83492791u;
  const std::uint32_t h = (static_cast<std::uint32_t>(c.x()) * kP1) ^ (static_cast<std::uint32_t>(c.y()) * kP2) ^
                          (static_cast<std::uint32_t>(c.z()) * kP3);
  // Spread the 32-bit hash over 64 bits so large power-of-two tables use their high slots.
  std::uint64_t x = h;
  x ^= x >> 16;
  x *= 0x45d9f3bULL;
  x ^= x >> 16;
  return x;
}

/// The home slot of a packed key in an open-addressing table of mask + 1 slots (a power of two)
/// of the host's scratch tables (downsampling cells, voxel grouping): Fibonacci hashing of the
/// key's bits, cheaper than unpacking it for spatial_hash.
inline std::size_t packed_key_slot(std::uint64_t key, std::size_t mask) {
  constexpr std::uint64_t kMultiplier = 0x9E3779B97F4A7C15ULL;
  constexpr int kShift = 20;
  return static_cast<std::size_t>((key * kMultiplier) >> kShift) & mask;
}

}  // namespace farlio::map
