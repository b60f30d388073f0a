#pragma once
// A box of voxel (or downsampling cell) coordinates that a set of keys is known to fall in: a
// scan's crop range around its origin. A key's offsets in the box pack into fewer bits than the
// 64-bit key, in the same order as the keys (z, then y, then x, as pack_key orders them), so a
// radix sort of the short keys takes fewer passes and gives the same order: the CUDA backend's
// sort_into_groups sorts ~30 bits instead of 64 (docs/cuda.md). A key outside the box is
// reported, and the caller then sorts the full keys. Shared by the CPU (tests) and CUDA.
#include <Eigen/Core>
#include <bit>
#include <cmath>
#include <cstdint>

#include "farlio/exec/hd.hpp"
#include "farlio/map/voxel_key.hpp"

namespace farlio::map {

struct KeyWindow {
  /// Short keys above this many bits save too little to be worth the extra kernels.
  static constexpr int kMaxBits = 48;
  /// Cells to spare on each side of the box (float rounding of the coordinates and the radius).
  static constexpr int kSpareCells = 1;

  VoxelCoord lo = VoxelCoord::Zero();  ///< lowest coordinate per axis
  int bits[3] = {0, 0, 0};             ///< per axis (x, y, z); 0: no window

  /// The cells of the points within radius_m of centre (cells of 1 / inv_cell_m metres); no
  /// window when the radius is not finite, the box leaves the key range or needs over kMaxBits.
  static KeyWindow around(const Eigen::Vector3d& centre, double radius_m, double inv_cell_m) {
    KeyWindow w;
    if (!(std::isfinite(radius_m) && radius_m >= 0.0 && std::isfinite(inv_cell_m) && inv_cell_m > 0.0)) return w;
    int bits[3];
    for (int a = 0; a < 3; ++a) {
      const double lo_cell = std::floor((centre[a] - radius_m) * inv_cell_m) - kSpareCells;
      const double hi_cell = std::floor((centre[a] + radius_m) * inv_cell_m) + kSpareCells;
      if (!(lo_cell >= -kKeyAxisOffset && hi_cell < kKeyAxisOffset)) return w;
      w.lo[a] = static_cast<int>(lo_cell);
      // offsets 0 .. span - 1 <= 2^bits - 2: the all-ones short key stays free for kEmptyKey
      const auto span = static_cast<std::uint32_t>(hi_cell - lo_cell + 1.0);
      bits[a] = static_cast<int>(std::bit_width(span));
    }
    if (bits[0] + bits[1] + bits[2] > kMaxBits) return KeyWindow{};
    for (int a = 0; a < 3; ++a) w.bits[a] = bits[a];
    return w;
  }

  [[nodiscard]] FARLIO_HD int total_bits() const { return bits[0] + bits[1] + bits[2]; }
  [[nodiscard]] FARLIO_HD bool usable() const { return total_bits() > 0; }
  /// The short key of kEmptyKey: all ones, above every short key of the box.
  [[nodiscard]] FARLIO_HD std::uint64_t empty_short_key() const { return (std::uint64_t{1} << total_bits()) - 1; }

  /// The short key of `key`; *outside becomes true when key is a voxel outside the box (its
  /// short key is then meaningless).
  FARLIO_HD std::uint64_t shorten(std::uint64_t key, bool* outside) const {
    if (key == kEmptyKey) return empty_short_key();
    const VoxelCoord d = unpack_key(key) - lo;
    std::uint64_t out = 0;
    int shift = 0;
    for (int a = 0; a < 3; ++a) {
      const std::int64_t limit = (std::int64_t{1} << bits[a]) - 2;
      if (d[a] < 0 || d[a] > limit) *outside = true;
      out |= (static_cast<std::uint64_t>(d[a]) & ((std::uint64_t{1} << bits[a]) - 1)) << shift;
      shift += bits[a];
    }
    return out;
  }

  /// The key of a short key of the box (kEmptyKey for empty_short_key()).
  [[nodiscard]] FARLIO_HD std::uint64_t expand(std::uint64_t short_key) const {
    if (short_key == empty_short_key()) return kEmptyKey;
    VoxelCoord c;
    int shift = 0;
    for (int a = 0; a < 3; ++a) {
      c[a] = lo[a] + static_cast<int>((short_key >> shift) & ((std::uint64_t{1} << bits[a]) - 1));
      shift += bits[a];
    }
    return pack_key(c);
  }
};

}  // namespace farlio::map
