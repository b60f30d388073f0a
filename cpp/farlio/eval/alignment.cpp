#include "farlio/eval/alignment.hpp"

#include <Eigen/SVD>
#include <string>

#include "farlio/core/error.hpp"

namespace farlio::eval {
namespace {
// Singular values below this fraction of the largest one count as zero for the rank test.
constexpr double kRelativeRankTolerance = 1e-12;
}  // namespace

Alignment umeyama_align(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                        bool with_scale) {
  if (source.size() != target.size() || source.empty()) {
    throw InputError("umeyama_align: point sets must be non-empty and of equal size (source " +
                     std::to_string(source.size()) + ", target " + std::to_string(target.size()) + ")");
  }
  const auto n = static_cast<double>(source.size());
  Eigen::Vector3d mean_source = Eigen::Vector3d::Zero(), mean_target = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < source.size(); ++k) {
    mean_source += source[k];
    mean_target += target[k];
  }
  mean_source /= n;
  mean_target /= n;

  // Cross-covariance Sigma = 1/n sum (y - my)(x - mx)^T and source variance.
  Mat3d covariance = Mat3d::Zero();
  double source_variance = 0.0;
  for (std::size_t k = 0; k < source.size(); ++k) {
    const Eigen::Vector3d x = source[k] - mean_source;
    covariance += (target[k] - mean_target) * x.transpose();
    source_variance += x.squaredNorm();
  }
  covariance /= n;
  source_variance /= n;

  const Eigen::JacobiSVD<Mat3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d singular = svd.singularValues();
  // S = diag(1, 1, det(U) det(V)) keeps R a proper rotation (no reflection).
  Eigen::Vector3d s_diag = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s_diag.z() = -1.0;
  const Mat3d rotation = svd.matrixU() * s_diag.asDiagonal() * svd.matrixV().transpose();

  Alignment a;
  a.rank_deficient = !(singular(1) > kRelativeRankTolerance * singular(0));
  if (with_scale && source_variance > 0.0) a.scale = singular.dot(s_diag) / source_variance;
  a.transform = SE3(rotation, mean_target - a.scale * (rotation * mean_source));
  return a;
}

}  // namespace farlio::eval
