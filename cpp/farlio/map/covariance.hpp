#pragma once
// Point covariances: the sample covariance of k neighbours, regularised with the Frobenius
// norm (paper eq. 1): Sigma = (C^-1 / ||C^-1||_F)^-1 with C = Sigma_hat + eps I, which equals
// ||C^-1||_F * C, so no eigen-decomposition is needed. Shared by CPU and CUDA.
#include <Eigen/Core>
#include <Eigen/LU>

#include "farlio/exec/hd.hpp"

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
/// far from the world origin.
struct CovarianceAccumulator {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  Eigen::Matrix3f sum_outer = Eigen::Matrix3f::Zero();
  int count = 0;

  FARLIO_HD explicit CovarianceAccumulator(const Eigen::Vector3f& o) : origin(o) {}
  FARLIO_HD void add(const Eigen::Vector3f& point) {
    const Eigen::Vector3f p = point - origin;
    sum += p;
    sum_outer += p * p.transpose();
    ++count;
  }
  FARLIO_HD Eigen::Matrix3f covariance() const {
    const float inv = 1.0f / static_cast<float>(count);
    const Eigen::Vector3f mean = sum * inv;
    return sum_outer * inv - mean * mean.transpose();
  }
};

/// Eigenvalues of a symmetric 3x3 matrix in ascending order, in closed form (trigonometric
/// solution of the characteristic cubic): no iteration, so it runs the same on CPU and GPU.
FARLIO_HD inline Eigen::Vector3f symmetric_eigenvalues(const Eigen::Matrix3f& a) {
  const float off2 = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
  const float q = a.trace() / 3.0f;
  const float d0 = a(0, 0) - q, d1 = a(1, 1) - q, d2 = a(2, 2) - q;
  const float p = sqrtf((d0 * d0 + d1 * d1 + d2 * d2 + 2.0f * off2) / 6.0f);
  if (p <= 0.0f) return Eigen::Vector3f::Constant(q);  // a multiple of the identity
  const Eigen::Matrix3f b = (a - q * Eigen::Matrix3f::Identity()) / p;
  const float r = fminf(1.0f, fmaxf(-1.0f, 0.5f * b.determinant()));
  constexpr float kThird = 1.0f / 3.0f, kTwoPiThirds = 2.0943951f;
  const float phi = acosf(r) * kThird;
  const float largest = q + 2.0f * p * cosf(phi);
  const float smallest = q + 2.0f * p * cosf(phi + kTwoPiThirds);
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

/// Frobenius-norm regularisation of eq. (1).
FARLIO_HD inline Eigen::Matrix3f regularize_frobenius(const Eigen::Matrix3f& sample_cov, float epsilon) {
  const Eigen::Matrix3f c = sample_cov + epsilon * Eigen::Matrix3f::Identity();
  // The inverse into a matrix first: Eigen 3.4's norm() of the inverse expression compiles to a
  // trap in device code (seen on an H200: every covariance kernel stopped there).
  const Eigen::Matrix3f inverse = c.inverse();
  return inverse.norm() * c;
}

}  // namespace farlio::map
