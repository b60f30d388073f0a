#include "farlio/fusion/initialization.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "farlio/core/time.hpp"

namespace farlio::fusion {
namespace {

/// Residual scales of the two kinds of equation, which weigh them against each other: the LiDAR
/// poses' relative position error (m) and the IMU's velocity increment error over a scan (m/s).
constexpr double kPositionEquationStd_m = 0.01;
constexpr double kVelocityEquationStd_m_s = 0.02;
/// Gauss-Newton passes that hold gravity at its magnitude.
constexpr int kGravityRefinements = 4;

/// The increments of every consecutive pair of poses; nullopt on an IMU gap.
std::optional<std::vector<ImuIncrement>> increments(const std::vector<WindowPose>& poses, const ImuMeanFn& imu,
                                                    std::int64_t step_ns) {
  std::vector<ImuIncrement> out;
  for (std::size_t k = 0; k + 1 < poses.size(); ++k) {
    auto inc = integrate_imu(imu, poses[k].stamp_ns, poses[k + 1].stamp_ns, step_ns);
    if (!inc) return std::nullopt;
    out.push_back(*inc);
  }
  return out;
}

/// Two unit vectors orthogonal to `d` and to each other.
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& d) {
  const Eigen::Vector3d a = std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = d.cross(a).normalized();
  B.col(1) = d.cross(B.col(0)).normalized();
  return B;
}

/// How gravity enters the unknowns: estimated freely (3 unknowns), as G d + B w (2 unknowns w
/// about a direction d), or known (none).
struct GravityModel {
  enum class Kind { kFree, kTangent, kKnown } kind = Kind::kFree;
  Eigen::Vector3d base = Eigen::Vector3d::Zero();                           ///< G d (tangent) or g (known)
  Eigen::Matrix<double, 3, 2> basis = Eigen::Matrix<double, 3, 2>::Zero();  ///< B (tangent)
  [[nodiscard]] int unknowns() const { return kind == Kind::kFree ? 3 : (kind == Kind::kTangent ? 2 : 0); }
};

struct Solution {
  Eigen::VectorXd x;  ///< v_0 .. v_{n-1}, then the gravity unknowns
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  double position_residual_m = 0.0;
};

/// Weighted linear least squares over all equations; nullopt when the system is rank deficient.
std::optional<Solution> solve(const std::vector<WindowPose>& poses, const std::vector<ImuIncrement>& inc,
                              const GravityModel& gm, const std::optional<double>& zero_velocity_std_m_s) {
  const int n = static_cast<int>(poses.size());
  const int nv = 3 * n, unknowns = nv + gm.unknowns();
  const int rows = 6 * (n - 1) + (zero_velocity_std_m_s ? nv : 0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, unknowns);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(rows);
  // gravity's contribution: A_g * unknowns_g + g_base
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3, gm.unknowns());
  if (gm.kind == GravityModel::Kind::kFree) G = Eigen::Matrix3d::Identity();
  if (gm.kind == GravityModel::Kind::kTangent) G = gm.basis;
  int r = 0;
  for (int k = 0; k + 1 < n; ++k) {
    const double dt = inc[k].dt_s;
    const Eigen::Matrix3d R = poses[k].body_pose.rotation();
    const Eigen::Vector3d dp = poses[k + 1].body_pose.translation() - poses[k].body_pose.translation();
    const double wp = 1.0 / kPositionEquationStd_m, wv = 1.0 / kVelocityEquationStd_m_s;
    // position: v_k dt + g dt^2 / 2 = dp - R alpha
    A.block<3, 3>(r, 3 * k) = wp * dt * Eigen::Matrix3d::Identity();
    if (gm.unknowns() > 0) A.block(r, nv, 3, gm.unknowns()) = wp * 0.5 * dt * dt * G;
    b.segment<3>(r) = wp * (dp - R * inc[k].position_m - 0.5 * dt * dt * gm.base);
    r += 3;
    // velocity: v_{k+1} - v_k - g dt = R beta
    A.block<3, 3>(r, 3 * (k + 1)) = wv * Eigen::Matrix3d::Identity();
    A.block<3, 3>(r, 3 * k) = -wv * Eigen::Matrix3d::Identity();
    if (gm.unknowns() > 0) A.block(r, nv, 3, gm.unknowns()) = -wv * dt * G;
    b.segment<3>(r) = wv * (R * inc[k].velocity_m_s + dt * gm.base);
    r += 3;
  }
  if (zero_velocity_std_m_s) {
    A.block(r, 0, nv, nv) = Eigen::MatrixXd::Identity(nv, nv) / *zero_velocity_std_m_s;
    r += nv;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < unknowns) return std::nullopt;
  Solution s;
  s.x = qr.solve(b);
  if (!s.x.allFinite()) return std::nullopt;
  s.gravity = gm.base + G * s.x.tail(gm.unknowns());
  double sum = 0.0;
  for (int k = 0; k + 1 < n; ++k) {
    const Eigen::Vector3d res = (A.block(6 * k, 0, 3, unknowns) * s.x - b.segment<3>(6 * k)) * kPositionEquationStd_m;
    sum += res.squaredNorm();
  }
  s.position_residual_m = n > 1 ? std::sqrt(sum / (n - 1)) : 0.0;
  return s;
}

}  // namespace

std::optional<ImuIncrement> integrate_imu(const ImuMeanFn& imu, std::int64_t start_ns, std::int64_t end_ns,
                                          std::int64_t step_ns) {
  ImuIncrement inc;
  if (end_ns <= start_ns || step_ns <= 0) return std::nullopt;
  const auto steps = std::max<std::int64_t>(1, (end_ns - start_ns + step_ns - 1) / step_ns);
  for (std::int64_t i = 0; i < steps; ++i) {
    const std::int64_t t0 = start_ns + (end_ns - start_ns) * i / steps;
    const std::int64_t t1 = start_ns + (end_ns - start_ns) * (i + 1) / steps;
    const auto m = imu(t0, t1);
    if (!m) return std::nullopt;
    const double dt = ns_to_seconds(t1 - t0);
    // the rotation at the sub-step's middle turns its mean specific force
    const Eigen::Matrix3d R_mid = inc.rotation * so3_exp(0.5 * dt * m->gyro_rad_s);
    const Eigen::Vector3d dv = R_mid * m->accel_m_s2 * dt;
    inc.position_m += inc.velocity_m_s * dt + 0.5 * dv * dt;
    inc.velocity_m_s += dv;
    inc.rotation = inc.rotation * so3_exp(dt * m->gyro_rad_s);
    inc.dt_s += dt;
  }
  return inc;
}

std::optional<Alignment> align_window(const std::vector<WindowPose>& poses, const ImuMeanFn& imu,
                                      const AlignmentOptions& options) {
  if (poses.size() < 2) return std::nullopt;
  const auto inc = increments(poses, imu, options.step_ns);
  if (!inc) return std::nullopt;
  Alignment out;
  std::optional<Solution> s;
  if (options.gravity_map_m_s2) {
    GravityModel known{GravityModel::Kind::kKnown, *options.gravity_map_m_s2, {}};
    s = solve(poses, *inc, known, options.zero_velocity_std_m_s);
  } else {
    s = solve(poses, *inc, GravityModel{}, options.zero_velocity_std_m_s);
    if (!s || s->gravity.norm() <= 0.0) return std::nullopt;
    out.gravity_norm_error = std::abs(s->gravity.norm() - options.gravity_m_s2) / options.gravity_m_s2;
    for (int i = 0; i < kGravityRefinements && s; ++i) {
      const Eigen::Vector3d d = s->gravity.normalized();
      GravityModel tangent{GravityModel::Kind::kTangent, options.gravity_m_s2 * d, tangent_basis(d)};
      s = solve(poses, *inc, tangent, options.zero_velocity_std_m_s);
    }
    if (!s) return std::nullopt;
    // the velocities that go with gravity at its magnitude
    GravityModel held{GravityModel::Kind::kKnown, options.gravity_m_s2 * s->gravity.normalized(), {}};
    s = solve(poses, *inc, held, options.zero_velocity_std_m_s);
  }
  if (!s) return std::nullopt;
  out.gravity_map_m_s2 = s->gravity;
  out.velocity_map_m_s = s->x.segment<3>(3 * static_cast<int>(poses.size() - 1));
  out.position_residual_m = s->position_residual_m;
  return out;
}

Eigen::Matrix3d level_from_map(const Eigen::Vector3d& gravity_map) {
  return Eigen::Quaterniond::FromTwoVectors(gravity_map, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace farlio::fusion
