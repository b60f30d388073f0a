#pragma once
// Point covariances: the sample covariance of k neighbours, regularised with the Frobenius
// norm (paper eq. 1): Sigma = (C^-1 / ||C^-1||_F)^-1 with C = Sigma_hat + eps I, which equals
// ||C^-1||_F * C, so no eigen-decomposition is needed. Shared by CPU and CUDA.
#include <Eigen/Core>
#include <Eigen/LU>  // determinant()

#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"

namespace farlio::map {

/// A symmetric 3x3 matrix stored as its upper triangle (xx xy xz yy yz zz).
struct Cov3 {
  float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  FARLIO_HD static Cov3 from(const Eigen::Matrix3f& m) {
    return {m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)};
  }
  FARLIO_HD Eigen::Matrix3f matrix() const {
    Eigen::Matrix3f m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
};

/// Accumulates neighbours one by one (no storage), then gives their covariance (1/k).
/// Points are taken relative to `origin` (the query point) so that float32 keeps its precision
/// far from the world origin. Only the 6 distinct sums of the symmetric outer products are kept:
/// the same floats as the full 3x3 sum, with 6 products a point instead of 9 (Eigen's 3x3 sum was
/// a fifth of the covariance stage, BM_CovarianceKnn).
struct CovarianceAccumulator {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  float sx = 0, sy = 0, sz = 0;                                // sum of p
  float sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;  // sum of p p^T, upper triangle
  int count = 0;

  FARLIO_HD explicit CovarianceAccumulator(const Eigen::Vector3f& o) : origin(o) {}
  FARLIO_HD void add(const Eigen::Vector3f& point) {
    const float x = point.x() - origin.x(), y = point.y() - origin.y(), z = point.z() - origin.z();
    sx += x;
    sy += y;
    sz += z;
    sxx += x * x;
    sxy += x * y;
    sxz += x * z;
    syy += y * y;
    syz += y * z;
    szz += z * z;
    ++count;
  }
  FARLIO_HD Eigen::Matrix3f covariance() const {
    const float inv = 1.0f / static_cast<float>(count);
    const float mx = sx * inv, my = sy * inv, mz = sz * inv;
    const float xx = sxx * inv - mx * mx, xy = sxy * inv - mx * my, xz = sxz * inv - mx * mz;
    const float yy = syy * inv - my * my, yz = syz * inv - my * mz, zz = szz * inv - mz * mz;
    Eigen::Matrix3f c;
    c << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return c;
  }
};

/// Eigenvalues of a symmetric 3x3 matrix in ascending order, in closed form without iteration
/// or trigonometry, so it runs the same on CPU and GPU. The trigonometric solution of the
/// characteristic cubic gives the smallest as q - 2 p cos(u) with cos(3u) = -r; c = cos(u) in
/// [1/2, 1] is written 1/2 + s, and s solves 4 s^3 + 6 s^2 = 1 - r, which Newton's method reaches
/// in two steps from a close start (the cubic is convex for s >= 0). acosf and two cosf cost
/// more than the rest of the shape test (BM_CovarianceKnn).
FARLIO_HD inline Eigen::Vector3f symmetric_eigenvalues(const Eigen::Matrix3f& a) {
  const float off2 = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
  const float q = a.trace() / 3.0f;
  const float d0 = a(0, 0) - q, d1 = a(1, 1) - q, d2 = a(2, 2) - q;
  const float p = sqrtf((d0 * d0 + d1 * d1 + d2 * d2 + 2.0f * off2) / 6.0f);
  if (p <= 0.0f) return Eigen::Vector3f::Constant(q);  // a multiple of the identity
  const Eigen::Matrix3f b = (a - q * Eigen::Matrix3f::Identity()) / p;
  const float r = exec::min_of(1.0f, exec::max_of(-1.0f, 0.5f * b.determinant()));
  constexpr float kSixth = 1.0f / 6.0f, kThird = 1.0f / 3.0f, kSqrt3 = 1.7320508f;
  // the start a - a^2 / 3 + 0.1757 a^3 with a = sqrt((1 - r) / 6): the root's series to second
  // order, its third coefficient fitted on [0, 2]; within 1.4e-3 of the root, so two steps reach
  // float precision (2e-11 in double)
  constexpr float kStartCubic = 0.1757f;
  constexpr int kNewtonSteps = 2;
  const float t = 1.0f - r;
  const float a0 = sqrtf(t * kSixth);
  float s = a0 * (1.0f - a0 * (kThird - kStartCubic * a0));
  for (int i = 0; i < kNewtonSteps; ++i) {
    const float slope = 12.0f * s * (s + 1.0f);
    if (slope > 0.0f) s -= (s * s * (4.0f * s + 6.0f) - t) / slope;
  }
  const float c = 0.5f + s;
  const float sin_u = sqrtf(exec::max_of(0.0f, 1.0f - c * c));
  const float smallest = q - 2.0f * p * c;
  const float largest = q + p * (c + kSqrt3 * sin_u);
  return {smallest, 3.0f * q - largest - smallest, largest};
}

/// What a stored point's w() says about its covariance (paper: valid or not; farlio also marks
/// line-like neighbourhoods, which a scan line or a thin pole produce).
enum class PointShape : int { NoCovariance = 0, Surface = 1, Line = 2 };

FARLIO_HD inline float shape_code(PointShape s) { return static_cast<float>(static_cast<int>(s)); }
FARLIO_HD inline bool has_covariance(const Eigen::Vector4f& p) { return p.w() > 0.5f; }
FARLIO_HD inline bool is_line_like(const Eigen::Vector4f& p) { return p.w() > 1.5f; }

/// Line-like: the middle eigenvalue of the regularised covariance is within `line_ratio` of the
/// smallest while the largest is not (`line_ratio` <= 1 never classifies a line).
FARLIO_HD inline PointShape classify_shape(const Eigen::Matrix3f& regularized_cov, float line_ratio) {
  if (line_ratio <= 1.0f) return PointShape::Surface;
  const Eigen::Vector3f ev = symmetric_eigenvalues(regularized_cov);
  const bool line = ev(1) < line_ratio * ev(0) && ev(2) > line_ratio * ev(0);
  return line ? PointShape::Line : PointShape::Surface;
}

/// The 6 distinct cofactors of a symmetric 3x3 matrix C (upper triangle of adj C) and det C: the
/// Frobenius regularisation's ||C^-1||_F and the GICP factor's inverse, without Eigen's generic
/// inverse.
struct SymmetricCofactors {
  float c00, c01, c02, c11, c12, c22, det;

  FARLIO_HD explicit SymmetricCofactors(const Eigen::Matrix3f& c) {
    const float a = c(0, 0), b = c(0, 1), d = c(0, 2), e = c(1, 1), f = c(1, 2), g = c(2, 2);
    c00 = e * g - f * f;
    c01 = d * f - b * g;
    c02 = b * f - d * e;
    c11 = a * g - d * d;
    c12 = b * d - a * f;
    c22 = a * e - b * b;
    det = a * c00 + b * c01 + d * c02;
  }
  /// ||adj C||_F
  [[nodiscard]] FARLIO_HD float adjugate_norm() const {
    return sqrtf(c00 * c00 + c11 * c11 + c22 * c22 + 2.0f * (c01 * c01 + c02 * c02 + c12 * c12));
  }
  /// C^-1 = adj C / det C
  [[nodiscard]] FARLIO_HD Eigen::Matrix3f inverse() const {
    const float inv_det = 1.0f / det;
    Eigen::Matrix3f adjugate;
    adjugate << c00, c01, c02, c01, c11, c12, c02, c12, c22;
    return adjugate * inv_det;
  }
};

/// Frobenius-norm regularisation of eq. (1): ||C^-1||_F = ||adj C||_F / |det C|, without forming
/// the inverse.
FARLIO_HD inline Eigen::Matrix3f regularize_frobenius(const Eigen::Matrix3f& sample_cov, float epsilon) {
  const Eigen::Matrix3f c = sample_cov + epsilon * Eigen::Matrix3f::Identity();
  const SymmetricCofactors cof(c);
  return (cof.adjugate_norm() / fabsf(cof.det)) * c;
}

}  // namespace farlio::map
