#pragma once
// Motion undistortion (paper section III-A): the sensor's motion during a scan as a linear
// function of time in the tangent space, xi(tau) = offset + rate * tau, where exp(xi(tau)) is
// the pose at time tau (s since scan start) of the sensor relative to its pose at the scan's
// end. A constant body twist w over a scan of duration D gives offset = -D w and rate = w; a
// regression over the fusion's pose history gives both directly. The per-point correction is a
// kernel body shared by the CPU executor and CUDA.
#include <Eigen/Core>
#include <cmath>

#include "farlio/exec/hd.hpp"

namespace farlio::deskew {

using Vec6f = Eigen::Matrix<float, 6, 1>;

struct ScanMotion {
  Vec6f offset = Vec6f::Zero();  ///< [rho; phi] at tau = 0
  Vec6f rate = Vec6f::Zero();    ///< d xi / d tau, per second

  /// Constant body twist (per second, [v; w], right-perturbation convention).
  static ScanMotion constant_twist(const Vec6f& twist, float duration_s) { return {-duration_s * twist, twist}; }
  [[nodiscard]] bool is_identity() const { return offset.isZero(0.0f) && rate.isZero(0.0f); }
};

/// SE(3) exponential in float (rotation matrix and translation), for the kernels.
FARLIO_HD inline void se3_exp(const Vec6f& xi, Eigen::Matrix3f& R, Eigen::Vector3f& t) {
  const Eigen::Vector3f rho = xi.head<3>(), phi = xi.tail<3>();
  const float th2 = phi.squaredNorm();
  Eigen::Matrix3f K;
  K << 0.0f, -phi.z(), phi.y(), phi.z(), 0.0f, -phi.x(), -phi.y(), phi.x(), 0.0f;
  const Eigen::Matrix3f K2 = K * K;
  float a, b, c;  // sin(th)/th, (1-cos th)/th^2, (th - sin th)/th^3
  constexpr float kSmallAngle2 = 1e-8f;
  if (th2 < kSmallAngle2) {
    a = 1.0f - th2 / 6.0f;
    b = 0.5f - th2 / 24.0f;
    c = 1.0f / 6.0f - th2 / 120.0f;
  } else {
    const float th = sqrtf(th2);
    a = sinf(th) / th;
    b = (1.0f - cosf(th)) / th2;
    c = (th - sinf(th)) / (th2 * th);
  }
  R = Eigen::Matrix3f::Identity() + a * K + b * K2;
  t = (Eigen::Matrix3f::Identity() + b * K + c * K2) * rho;
}

/// The point measured at tau, expressed in the sensor frame at the scan's end.
FARLIO_HD inline Eigen::Vector3f deskew_point(const ScanMotion& m, const Eigen::Vector3f& p, float tau_s) {
  Eigen::Matrix3f R;
  Eigen::Vector3f t;
  se3_exp(m.offset + m.rate * tau_s, R, t);
  return R * p + t;
}

}  // namespace farlio::deskew
