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

/// The motion sampled at kSegments + 1 evenly spaced times over the scan: exact poses, between
/// which a point's pose is interpolated linearly, so that the per-point correction costs a few
/// multiply-adds instead of an SE(3) exponential (sin, cos) per point. Interpolating a rotation
/// that turns by d over a segment deviates from it by about d^2 / 8: at 3 rad/s over a 0.1 s
/// scan, 2.7e-6 rad, 0.14 mm at 50 m, and the translation as little at 70 m/s
/// (tests/cpp/test_deskew.cpp bounds both against deskew_point). Built on the host; 3.1 KB, a
/// kernel parameter.
struct DeskewTable {
  static constexpr int kSegments = 64;
  static constexpr int kPoseFloats = 12;  ///< R column-major (9), then t (3)
  float inv_step = 0.0f;                  ///< segments per second
  float poses[kSegments + 1][kPoseFloats] = {};

  /// The table of `motion` over [0, duration_s] (a non-positive duration: the pose at 0).
  static DeskewTable sample(const ScanMotion& motion, float duration_s) {
    DeskewTable table;
    const float step = duration_s > 0.0f ? duration_s / kSegments : 0.0f;
    table.inv_step = step > 0.0f ? 1.0f / step : 0.0f;
    for (int k = 0; k <= kSegments; ++k) {
      Eigen::Matrix3f R;
      Eigen::Vector3f t;
      se3_exp(motion.offset + motion.rate * (step * static_cast<float>(k)), R, t);
      for (int i = 0; i < 9; ++i) table.poses[k][i] = R.data()[i];
      for (int i = 0; i < 3; ++i) table.poses[k][9 + i] = t[i];
    }
    return table;
  }
};

/// deskew_point with the pose interpolated from `table` (tau outside the scan: the end segment,
/// extrapolated).
FARLIO_HD inline Eigen::Vector3f deskew_point(const DeskewTable& table, const Eigen::Vector3f& p, float tau_s) {
  const float x = tau_s * table.inv_step;
  // written so that a NaN tau takes the first segment rather than an index out of the table
  const float clamped = x >= 0.0f ? (x > DeskewTable::kSegments - 1 ? DeskewTable::kSegments - 1 : x) : 0.0f;
  const int k = static_cast<int>(clamped);
  const float a = x - static_cast<float>(k), b = 1.0f - a;
  const float* p0 = table.poses[k];
  const float* p1 = table.poses[k + 1];
  float T[DeskewTable::kPoseFloats];
  for (int i = 0; i < DeskewTable::kPoseFloats; ++i) T[i] = b * p0[i] + a * p1[i];
  return {T[0] * p.x() + T[3] * p.y() + T[6] * p.z() + T[9], T[1] * p.x() + T[4] * p.y() + T[7] * p.z() + T[10],
          T[2] * p.x() + T[5] * p.y() + T[8] * p.z() + T[11]};
}

}  // namespace farlio::deskew
