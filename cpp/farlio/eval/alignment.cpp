#include "farlio/eval/alignment.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "farlio/core/error.hpp"

namespace farlio::eval {
namespace {
// Singular values below this fraction of the largest one count as zero for the rank test.
constexpr double kRelativeRankTolerance = 1e-12;
// A spread below this fraction of the largest one counts as none (noise-free collinear data):
// the square root of kRelativeRankTolerance, spreads being square roots of singular values.
constexpr double kRelativeSpreadTolerance = 1e-6;

/// Sigma = 1/n sum (y - my)(x - mx)^T of target points y and source points x, with both means.
struct CrossCovariance {
  Eigen::Vector3d mean_source = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_target = Eigen::Vector3d::Zero();
  Mat3d matrix = Mat3d::Zero();
  double source_variance = 0.0;  ///< 1/n sum |x - mx|^2
};

void check_sizes(const char* what, std::size_t source, std::size_t target) {
  if (source != target || source == 0) {
    throw InputError(std::string(what) + ": inputs must be non-empty and of equal size (source " +
                     std::to_string(source) + ", target " + std::to_string(target) + ")");
  }
}

CrossCovariance cross_covariance(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target) {
  CrossCovariance c;
  const auto n = static_cast<double>(source.size());
  for (std::size_t k = 0; k < source.size(); ++k) {
    c.mean_source += source[k];
    c.mean_target += target[k];
  }
  c.mean_source /= n;
  c.mean_target /= n;
  for (std::size_t k = 0; k < source.size(); ++k) {
    const Eigen::Vector3d x = source[k] - c.mean_source;
    c.matrix += (target[k] - c.mean_target) * x.transpose();
    c.source_variance += x.squaredNorm();
  }
  c.matrix /= n;
  c.source_variance /= n;
  return c;
}

/// The rotation R maximising tr(R^T m) (U diag(1, 1, det(U) det(V)) V^T: never a reflection).
Mat3d nearest_rotation(const Eigen::JacobiSVD<Mat3d>& svd) {
  Eigen::Vector3d s_diag = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s_diag.z() = -1.0;
  return svd.matrixU() * s_diag.asDiagonal() * svd.matrixV().transpose();
}

Mat3d nearest_rotation(const Mat3d& m) {
  return nearest_rotation(Eigen::JacobiSVD<Mat3d>(m, Eigen::ComputeFullU | Eigen::ComputeFullV));
}

/// The alignment with rotation R: the least-squares scale for R (when asked for and determined)
/// and the translation taking the source centroid onto the target centroid.
Alignment with_rotation(const Mat3d& rotation, const CrossCovariance& c, bool with_scale) {
  Alignment a;
  if (with_scale && c.source_variance > 0.0) a.scale = (rotation.transpose() * c.matrix).trace() / c.source_variance;
  a.transform = SE3(rotation, c.mean_target - a.scale * (rotation * c.mean_source));
  return a;
}

bool is_rank_deficient(const Eigen::Vector3d& singular_values) {
  return !(singular_values(1) > kRelativeRankTolerance * singular_values(0));
}

std::vector<Eigen::Vector3d> positions(std::span<const SE3> poses) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(poses.size());
  for (const SE3& p : poses) out.push_back(p.translation());
  return out;
}

double rms_residual_m(const Alignment& a, std::span<const Eigen::Vector3d> source,
                      std::span<const Eigen::Vector3d> target) {
  double sum = 0.0;
  for (std::size_t k = 0; k < source.size(); ++k) sum += (target[k] - a.apply(source[k])).squaredNorm();
  return std::sqrt(sum / static_cast<double>(source.size()));
}

/// R = rotation about `axis` (unit, target frame) times `rotation`, the angle maximising
/// sum_k tr(R_target_k^T R R_source_k) = tr(R_axis(theta) M), M = sum_k rotation R_source_k R_target_k^T:
/// tr(R_axis(theta) M) = a^T M a + cos(theta) (tr M - a^T M a) + sin(theta) tr(hat(a) M).
Mat3d orient_about_axis(const Mat3d& rotation, const Eigen::Vector3d& axis, std::span<const SE3> source,
                        std::span<const SE3> target) {
  Mat3d m = Mat3d::Zero();
  for (std::size_t k = 0; k < source.size(); ++k)
    m += rotation * source[k].rotation() * target[k].rotation().transpose();
  const double angle = std::atan2((hat(axis) * m).trace(), m.trace() - axis.dot(m * axis));
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix() * rotation;
}

/// The rotation maximising sum_k tr(R_target_k^T R R_source_k): the nearest rotation to
/// sum_k R_target_k R_source_k^T.
Mat3d orientation_rotation(std::span<const SE3> source, std::span<const SE3> target) {
  Mat3d m = Mat3d::Zero();
  for (std::size_t k = 0; k < source.size(); ++k) m += target[k].rotation() * source[k].rotation().transpose();
  return nearest_rotation(m);
}

}  // namespace

Alignment umeyama_align(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                        bool with_scale) {
  check_sizes("umeyama_align", source.size(), target.size());
  const CrossCovariance c = cross_covariance(source, target);
  const Eigen::JacobiSVD<Mat3d> svd(c.matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Alignment a = with_rotation(nearest_rotation(svd), c, with_scale);
  a.rank_deficient = is_rank_deficient(svd.singularValues());
  return a;
}

Alignment align_poses(std::span<const SE3> source, std::span<const SE3> target, bool with_scale,
                      double min_spread_to_residual) {
  check_sizes("align_poses", source.size(), target.size());
  const std::vector<Eigen::Vector3d> source_positions = positions(source), target_positions = positions(target);
  const CrossCovariance c = cross_covariance(source_positions, target_positions);
  const Eigen::JacobiSVD<Mat3d> svd(c.matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Mat3d umeyama_rotation = nearest_rotation(svd);
  Alignment a = with_rotation(umeyama_rotation, c, with_scale);
  a.rank_deficient = is_rank_deficient(svd.singularValues());

  const Eigen::Vector3d spread_m = svd.singularValues().cwiseMax(0.0).cwiseSqrt();
  const double min_spread_m = std::max(min_spread_to_residual * rms_residual_m(a, source_positions, target_positions),
                                       kRelativeSpreadTolerance * spread_m(0));
  const auto undetermined = [&](double spread) { return !(spread > min_spread_m); };
  if (!undetermined(spread_m(1))) return a;

  const bool rank_deficient = a.rank_deficient;
  if (undetermined(spread_m(0))) {
    a = with_rotation(orientation_rotation(source, target), c, /*with_scale=*/false);
    a.method = AlignmentMethod::kOrientation;
  } else {
    // the principal direction of the target positions (that of the source, rotated, when the source is the line)
    const Eigen::Vector3d axis = svd.matrixU().col(0);
    a = with_rotation(orient_about_axis(umeyama_rotation, axis, source, target), c, with_scale);
    a.method = AlignmentMethod::kUmeyamaOrientation;
  }
  a.rank_deficient = rank_deficient;
  return a;
}

Alignment align_origin(std::span<const SE3> source, std::span<const SE3> target) {
  check_sizes("align_origin", source.size(), target.size());
  Alignment a;
  a.transform = target.front() * source.front().inverse();
  a.method = AlignmentMethod::kOrigin;
  return a;
}

}  // namespace farlio::eval
