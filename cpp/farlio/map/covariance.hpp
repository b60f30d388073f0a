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

/// Frobenius-norm regularisation of eq. (1).
FARLIO_HD inline Eigen::Matrix3f regularize_frobenius(const Eigen::Matrix3f& sample_cov, float epsilon) {
  const Eigen::Matrix3f c = sample_cov + epsilon * Eigen::Matrix3f::Identity();
  return c.inverse().norm() * c;
}

}  // namespace farlio::map
