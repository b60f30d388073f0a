#pragma once
// Small math helpers that Eigen 3.4 offers on the host only (allFinite is not a device
// function), written once for the shared kernel bodies.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "farlio/exec/hd.hpp"

namespace farlio::exec {

FARLIO_HD inline bool is_finite(float x) {
#ifdef FARLIO_ON_DEVICE
  return isfinite(x);
#else
  return std::isfinite(x);
#endif
}

/// True if every coefficient of a fixed-size float matrix or vector is finite.
template <typename Derived>
FARLIO_HD bool all_finite(const Derived& m) {
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) {
      if (!is_finite(m(r, c))) return false;
    }
  }
  return true;
}

/// floor(x) as an int for |x| < 2^31 (beyond, as undefined as static_cast<int>(floorf(x))). On
/// the host the truncation toward zero is corrected by one below zero: x86-64's baseline (SSE2)
/// has no float floor instruction, and floorf's emulation took a tenth of the preprocessing
/// (docs/performance.md, "Voxel keys without floorf's emulation"). The same integer as floorf over that range.
FARLIO_HD inline int floor_to_int(float x) {
#ifdef FARLIO_ON_DEVICE
  return static_cast<int>(floorf(x));
#else
  const int t = static_cast<int>(x);
  return t - static_cast<int>(x < static_cast<float>(t));
#endif
}

/// The smaller / larger of two floats without a NaN rule: one minss / maxss on the host, where
/// fminf and fmaxf are calls into libm (they must return the number when the other is NaN).
FARLIO_HD inline float min_of(float a, float b) { return a < b ? a : b; }
FARLIO_HD inline float max_of(float a, float b) { return a > b ? a : b; }

/// The bits of a float and back (memcpy: defined behaviour on the host and the device). For
/// x >= +0 the bits order as the values do.
FARLIO_HD inline std::uint32_t float_bits(float x) {
  std::uint32_t b;
  memcpy(&b, &x, sizeof b);
  return b;
}
FARLIO_HD inline float float_from_bits(std::uint32_t b) {
  float x;
  memcpy(&x, &b, sizeof x);
  return x;
}

/// log(1 + x) for x >= 0 (the Cauchy kernel's cost), within 3e-7 of the exact value relative
/// (2 to 3 float ulps; tests/cpp/test_shared_bodies.cpp): 1 + x = 2^e m with m in [sqrt(1/2), sqrt(2)), log m =
/// 2 atanh((m - 1) / (m + 1)) by its series, and the rounding of 1 + x corrected to first order.
/// glibc's log1pf saves and restores the floating-point environment on every call, which would make
/// it a twentieth of a frame's registration. Infinity and NaN come back as they are.
FARLIO_HD inline float log1p_nonnegative(float x) {
  if (!(x < 3.0e38f)) return x;
  constexpr float kLn2 = 0.693147180559945f, kSqrt2 = 1.41421356f;
  constexpr std::uint32_t kMantissaMask = 0x007fffffu, kExponentOne = 0x3f800000u;
  constexpr int kMantissaBits = 23, kExponentBias = 127;
  const float y = 1.0f + x;
  const std::uint32_t bits = float_bits(y);
  int e = static_cast<int>(bits >> kMantissaBits) - kExponentBias;
  float m = float_from_bits((bits & kMantissaMask) | kExponentOne);  // [1, 2)
  if (m > kSqrt2) {
    m *= 0.5f;
    ++e;
  }
  const float s = (m - 1.0f) / (m + 1.0f), s2 = s * s;  // |s| <= 0.172
  const float series =
      2.0f * s * (1.0f + s2 * (1.0f / 3.0f + s2 * (1.0f / 5.0f + s2 * (1.0f / 7.0f + s2 * (1.0f / 9.0f)))));
  return static_cast<float>(e) * kLn2 + series + (x - (y - 1.0f)) / y;
}

}  // namespace farlio::exec
