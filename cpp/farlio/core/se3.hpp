#pragma once
// Rigid-body transforms in double precision: SO(3)/SE(3) exponential and logarithm maps.
// Tangent vectors of SE(3) are ordered [translation part rho; rotation part phi], and
// perturbations are applied on the left: T' = exp(xi) * T.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace farlio {

using Vec6d = Eigen::Matrix<double, 6, 1>;
using Mat6d = Eigen::Matrix<double, 6, 6>;
using Mat3d = Eigen::Matrix3d;
using Mat4d = Eigen::Matrix4d;

/// Skew-symmetric matrix such that hat(a) * b == a.cross(b).
Mat3d hat(const Eigen::Vector3d& a);
/// Rotation matrix of the rotation vector phi (Rodrigues).
Mat3d so3_exp(const Eigen::Vector3d& phi);
/// Rotation vector of a rotation matrix, |phi| <= pi.
Eigen::Vector3d so3_log(const Mat3d& R);
/// Left Jacobian of SO(3) and its inverse (maps rotation-vector rates to angular velocity).
Mat3d so3_left_jacobian(const Eigen::Vector3d& phi);
Mat3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi);

/// A rigid transform: rotation (unit quaternion) and translation.
class SE3 {
 public:
  SE3() = default;
  SE3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : q_(q.normalized()), t_(t) {}
  SE3(const Mat3d& R, const Eigen::Vector3d& t) : q_(Eigen::Quaterniond(R).normalized()), t_(t) {}
  /// From a 4x4 homogeneous matrix (the rotation block is re-orthonormalised).
  static SE3 from_matrix(const Mat4d& m);
  static SE3 identity() { return {}; }
  static SE3 exp(const Vec6d& xi);
  [[nodiscard]] Vec6d log() const;

  [[nodiscard]] const Eigen::Quaterniond& quaternion() const { return q_; }
  [[nodiscard]] Mat3d rotation() const { return q_.toRotationMatrix(); }
  [[nodiscard]] const Eigen::Vector3d& translation() const { return t_; }
  Eigen::Vector3d& translation() { return t_; }
  [[nodiscard]] Mat4d matrix() const;

  [[nodiscard]] SE3 inverse() const;
  SE3 operator*(const SE3& o) const { return {q_ * o.q_, t_ + q_ * o.t_}; }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return q_ * p + t_; }

  /// Rotation angle of this transform in radians, in [0, pi].
  [[nodiscard]] double angle_rad() const;

 private:
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
};

/// The adjoint of T for [rho; phi] tangents: T exp(xi) T^-1 = exp(adjoint(T) xi), i.e.
/// [[R, hat(t) R], [0, R]]. A right perturbation xi of A becomes adjoint(B^-1) xi of A * B.
Mat6d adjoint(const SE3& T);

/// Geodesic interpolation a -> b: a * exp(s * log(a^-1 b)) for s in [0, 1] (extrapolates outside).
SE3 interpolate(const SE3& a, const SE3& b, double s);

}  // namespace farlio
