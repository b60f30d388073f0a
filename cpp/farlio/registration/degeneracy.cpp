#include "farlio/registration/degeneracy.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

namespace farlio::registration {
namespace {

struct Principal {
  Eigen::Vector3d std;
  Eigen::Matrix3d axes;
};

/// Principal stds of a 3x3 covariance, largest first.
Principal principal_stds(const Eigen::Matrix3d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (covariance + covariance.transpose()));
  Principal p;
  for (int i = 0; i < 3; ++i) {  // eigenvalues ascending: reverse
    p.std(i) = std::sqrt(std::max(0.0, es.eigenvalues()(2 - i)));
    p.axes.col(i) = es.eigenvectors().col(2 - i);
  }
  return p;
}

int count_over(const Eigen::Vector3d& stds, double threshold) {
  return static_cast<int>((stds.array() > threshold).count());
}

}  // namespace

Mat6d body_information(const Mat6d& H_sensor, const SE3& T_body_sensor, double covariance_scale) {
  // a right perturbation xi of the sensor pose is adjoint(T_body_sensor) xi of the body pose
  const Mat6d A_inv = adjoint(T_body_sensor.inverse());
  const Mat6d H = A_inv.transpose() * H_sensor * A_inv / covariance_scale;
  return 0.5 * (H + H.transpose());
}

Mat6d covariance_from_information(const Mat6d& information) {
  const Eigen::SelfAdjointEigenSolver<Mat6d> es(information);
  const double min_information = 1.0 / (kUnconstrainedStd * kUnconstrainedStd);
  const Vec6d inverse = es.eigenvalues().cwiseMax(min_information).cwiseInverse();
  return es.eigenvectors() * inverse.asDiagonal() * es.eigenvectors().transpose();
}

Degeneracy analyze_degeneracy(const Mat6d& covariance, double inliers, const RegistrationConfig& config) {
  const Principal t = principal_stds(covariance.topLeftCorner<3, 3>());
  const Principal r = principal_stds(covariance.bottomRightCorner<3, 3>());
  Degeneracy d;
  d.translation_std_m = t.std;
  d.translation_axes = t.axes;
  d.rotation_std_rad = r.std;
  d.rotation_axes = r.axes;
  // both the std and the std per matched point: a scan with few points (a small room) is loose
  // everywhere without being degenerate along any direction
  const double point_std_limit_m = config.degenerate_translation_point_std_m / std::sqrt(std::max(1.0, inliers));
  d.degenerate_translations = count_over(t.std, std::max(config.degenerate_translation_std_m, point_std_limit_m));
  d.degenerate_rotations = count_over(r.std, config.degenerate_rotation_std_rad);
  return d;
}

Eigen::Matrix<double, 6, Eigen::Dynamic> degenerate_directions(const Degeneracy& d) {
  Eigen::Matrix<double, 6, Eigen::Dynamic> C =
      Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, d.degenerate_translations + d.degenerate_rotations);
  // the stds are sorted largest first: the degenerate axes are the first columns of each block
  for (int i = 0; i < d.degenerate_translations; ++i) C.col(i).head<3>() = d.translation_axes.col(i);
  for (int i = 0; i < d.degenerate_rotations; ++i)
    C.col(d.degenerate_translations + i).tail<3>() = d.rotation_axes.col(i);
  return C;
}

Vec6d step_without_degenerate_directions(const Mat6d& H, const Vec6d& b, const Degeneracy& d) {
  if (!d.degenerate()) return H.ldlt().solve(-b);
  const Eigen::Matrix<double, 6, Eigen::Dynamic> C = degenerate_directions(d);
  const auto m = C.cols();
  if (m >= 6) return Vec6d::Zero();
  // N: an orthonormal basis of the steps orthogonal to every degenerate direction
  const Mat6d Q = Eigen::HouseholderQR<Eigen::Matrix<double, 6, Eigen::Dynamic>>(C).householderQ();
  const Eigen::Matrix<double, 6, Eigen::Dynamic> N = Q.rightCols(6 - m);
  const Eigen::MatrixXd H_reduced = N.transpose() * H * N;
  const Eigen::VectorXd y = H_reduced.ldlt().solve(-(N.transpose() * b));
  return N * y;
}

Mat6d release_degenerate_directions(const Mat6d& covariance, const Degeneracy& d) {
  const Eigen::Matrix<double, 6, Eigen::Dynamic> C = degenerate_directions(d);
  return covariance + kUnconstrainedStd * kUnconstrainedStd * C * C.transpose();
}

Mat6d release_degenerate_rotations(const Mat6d& covariance, const Degeneracy& d) {
  Degeneracy rotations = d;
  rotations.degenerate_translations = 0;
  return release_degenerate_directions(covariance, rotations);
}

Eigen::Vector3d degenerate_translation_step(const LinearSystem& system, double damping, const SE3& T_body_sensor,
                                            const Degeneracy& d) {
  Eigen::Vector3d step = Eigen::Vector3d::Zero();
  if (d.degenerate_translations == 0) return step;
  const Vec6d dx_sensor = (system.H + damping * Mat6d::Identity()).ldlt().solve(-system.b);
  if (!dx_sensor.allFinite()) return step;
  // a right perturbation xi of the sensor pose is adjoint(T_body_sensor) xi of the body pose
  const Eigen::Vector3d dt_body = (adjoint(T_body_sensor) * dx_sensor).head<3>();
  for (int i = 0; i < d.degenerate_translations; ++i) {
    const Eigen::Vector3d axis = d.translation_axes.col(i);
    step += axis * axis.dot(dt_body);
  }
  return step;
}

}  // namespace farlio::registration
