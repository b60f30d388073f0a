#pragma once
// The Gauss-Newton linear system of a registration: what the solver, an EKF update and a
// degeneracy check (eigenvalues of H) need. Accumulated in double.
#include <Eigen/Core>

namespace farlio::registration {

using Mat6d = Eigen::Matrix<double, 6, 6>;
using Vec6d = Eigen::Matrix<double, 6, 1>;

struct LinearSystem {
  Mat6d H = Mat6d::Zero();  ///< sum of w J^T Omega J (right perturbation, [translation; rotation])
  Vec6d b = Vec6d::Zero();  ///< sum of w J^T Omega r
  double error = 0.0;       ///< sum of the robust costs
  long inliers = 0;         ///< correspondences within the threshold

  LinearSystem& operator+=(const LinearSystem& o) {
    H += o.H;
    b += o.b;
    error += o.error;
    inliers += o.inliers;
    return *this;
  }
  friend LinearSystem operator+(LinearSystem a, const LinearSystem& o) { return a += o; }
};

}  // namespace farlio::registration
