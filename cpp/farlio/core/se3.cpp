#include "farlio/core/se3.hpp"

#include <cmath>

namespace farlio {
namespace {
// Below this angle the series expansions replace the closed forms (sin(x)/x etc.).
constexpr double kSmallAngleRad = 1e-8;
}  // namespace

Mat3d hat(const Eigen::Vector3d& a) {
  Mat3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

Mat3d so3_exp(const Eigen::Vector3d& phi) {
  const double th = phi.norm();
  if (th < kSmallAngleRad) return Mat3d::Identity() + hat(phi);
  return Eigen::AngleAxisd(th, phi / th).toRotationMatrix();
}

Eigen::Vector3d so3_log(const Mat3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Mat3d so3_left_jacobian(const Eigen::Vector3d& phi) {
  const double th = phi.norm();
  const Mat3d K = hat(phi);
  if (th < kSmallAngleRad) return Mat3d::Identity() + 0.5 * K;
  const double th2 = th * th;
  return Mat3d::Identity() + (1.0 - std::cos(th)) / th2 * K + (th - std::sin(th)) / (th2 * th) * K * K;
}

Mat3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double th = phi.norm();
  const Mat3d K = hat(phi);
  if (th < kSmallAngleRad) return Mat3d::Identity() - 0.5 * K;
  const double half = 0.5 * th;
  const double cot = std::cos(half) / std::sin(half);
  return Mat3d::Identity() - 0.5 * K + (1.0 / (th * th)) * (1.0 - half * cot) * K * K;
}

SE3 SE3::from_matrix(const Mat4d& m) { return {Mat3d(m.block<3, 3>(0, 0)), Eigen::Vector3d(m.block<3, 1>(0, 3))}; }

SE3 SE3::exp(const Vec6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  const double th = phi.norm();
  Eigen::Quaterniond q = th < kSmallAngleRad ? Eigen::Quaterniond(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z())
                                             : Eigen::Quaterniond(Eigen::AngleAxisd(th, phi / th));
  return {q, so3_left_jacobian(phi) * rho};
}

Vec6d SE3::log() const {
  const Eigen::Vector3d phi = so3_log(rotation());
  Vec6d xi;
  xi.head<3>() = so3_left_jacobian_inverse(phi) * t_;
  xi.tail<3>() = phi;
  return xi;
}

Mat4d SE3::matrix() const {
  Mat4d m = Mat4d::Identity();
  m.block<3, 3>(0, 0) = rotation();
  m.block<3, 1>(0, 3) = t_;
  return m;
}

SE3 SE3::inverse() const {
  const Eigen::Quaterniond qi = q_.conjugate();
  return {qi, -(qi * t_)};
}

double SE3::angle_rad() const {
  const double w = std::min(1.0, std::abs(q_.w()));
  return 2.0 * std::atan2(q_.vec().norm(), w);
}

SE3 interpolate(const SE3& a, const SE3& b, double s) { return a * SE3::exp(s * (a.inverse() * b).log()); }

Mat6d adjoint(const SE3& T) {
  const Mat3d R = T.rotation();
  Mat6d A = Mat6d::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = hat(T.translation()) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

}  // namespace farlio
