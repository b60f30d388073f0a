#include "farlio/preprocess/downsampling_keys.hpp"

#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "farlio/map/voxel_key.hpp"

namespace farlio::preprocess {
namespace {

#if defined(__SSE2__)
/// Four points' keys: the operations of downsampling_key lane by lane, in the same order, so the
/// same floats and integers.
inline void four_keys(const float* xyz, const PreprocessParams& pp, std::uint64_t* keys) {
  // x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3  ->  x0..x3, y0..y3, z0..z3
  const __m128 a = _mm_loadu_ps(xyz), b = _mm_loadu_ps(xyz + 4), c = _mm_loadu_ps(xyz + 8);
  const __m128 x2y2x3y3 = _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 1, 3, 2));
  const __m128 y0z0y1z1 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 0, 2, 1));
  const __m128 x = _mm_shuffle_ps(a, x2y2x3y3, _MM_SHUFFLE(2, 0, 3, 0));
  const __m128 y = _mm_shuffle_ps(y0z0y1z1, x2y2x3y3, _MM_SHUFFLE(3, 1, 2, 0));
  const __m128 z = _mm_shuffle_ps(y0z0y1z1, c, _MM_SHUFFLE(3, 0, 3, 1));
  // the range crop: x x + (y y + z z), Eigen's order in squaredNorm, finite and within [min, max];
  // a finite squared range also means finite coordinates, map::point_key's first test
  const __m128 r2 = _mm_add_ps(_mm_mul_ps(x, x), _mm_add_ps(_mm_mul_ps(y, y), _mm_mul_ps(z, z)));
  const __m128 finite = _mm_cmplt_ps(r2, _mm_set1_ps(std::numeric_limits<float>::infinity()));
  const __m128 in_range =
      _mm_and_ps(_mm_cmpge_ps(r2, _mm_set1_ps(pp.crop.min_range2)), _mm_cmple_ps(r2, _mm_set1_ps(pp.crop.max_range2)));
  __m128i keep = _mm_castps_si128(_mm_and_ps(finite, in_range));
  // the cell: exec::floor_to_int per axis (truncation, minus one where that rounded up), then
  // map::in_key_range and map::pack_key
  const __m128 inv = _mm_set1_ps(pp.inv_cell_m);
  const __m128i lim = _mm_set1_epi32(map::kKeyAxisOffset - 1), neg_lim = _mm_set1_epi32(1 - map::kKeyAxisOffset);
  const __m128i offset = _mm_set1_epi32(map::kKeyAxisOffset);
  const __m128i axis_mask = _mm_set1_epi32(static_cast<int>(map::kKeyAxisMask));
  __m128i axis[3];
  const __m128 coords[3] = {x, y, z};
  for (int k = 0; k < 3; ++k) {
    const __m128 v = _mm_mul_ps(coords[k], inv);
    const __m128i t = _mm_cvttps_epi32(v);
    const __m128i cell = _mm_add_epi32(t, _mm_castps_si128(_mm_cmplt_ps(v, _mm_cvtepi32_ps(t))));
    keep = _mm_and_si128(keep, _mm_and_si128(_mm_cmpgt_epi32(cell, neg_lim), _mm_cmplt_epi32(cell, lim)));
    axis[k] = _mm_and_si128(_mm_add_epi32(cell, offset), axis_mask);
  }
  const __m128i zero = _mm_setzero_si128(), ones = _mm_set1_epi32(-1);
  const auto pack = [&](__m128i ax, __m128i ay, __m128i az, __m128i kept) {
    const __m128i key = _mm_or_si128(
        ax, _mm_or_si128(_mm_slli_epi64(ay, map::kKeyBitsPerAxis), _mm_slli_epi64(az, 2 * map::kKeyBitsPerAxis)));
    return _mm_or_si128(key, _mm_xor_si128(kept, ones));  // a dropped point: kEmptyKey (all ones)
  };
  const __m128i lo = pack(_mm_unpacklo_epi32(axis[0], zero), _mm_unpacklo_epi32(axis[1], zero),
                          _mm_unpacklo_epi32(axis[2], zero), _mm_unpacklo_epi32(keep, keep));
  const __m128i hi = pack(_mm_unpackhi_epi32(axis[0], zero), _mm_unpackhi_epi32(axis[1], zero),
                          _mm_unpackhi_epi32(axis[2], zero), _mm_unpackhi_epi32(keep, keep));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(keys), lo);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(keys + 2), hi);
}
#endif

}  // namespace

void downsampling_keys(const Vec3f* points, std::size_t n, const PreprocessParams& pp, std::uint64_t* keys) {
  std::size_t i = 0;
#if defined(__SSE2__)
  static_assert(sizeof(Vec3f) == 3 * sizeof(float), "the SSE2 path reads the points as packed xyz floats");
  for (; i + 4 <= n; i += 4) four_keys(points[i].data(), pp, keys + i);
#endif
  for (; i < n; ++i) keys[i] = downsampling_key(points[i], pp);
}

std::size_t drop_non_finite(const Vec3f* points, const float* times, std::size_t n, std::uint64_t* keys) {
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (finite_point(points[i], times ? times + i : nullptr)) continue;
    keys[i] = map::kEmptyKey;
    ++dropped;
  }
  return dropped;
}

}  // namespace farlio::preprocess
