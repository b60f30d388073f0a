#include "farlio/io/rigid_transform.hpp"

#include "farlio/core/error.hpp"

namespace farlio::io {

SE3 rigid_transform_from_matrix(const Mat4d& m, const std::string& what) {
  auto bad = [&](const std::string& why) { return InputError(what + ": " + why); };
  if (!m.allFinite()) throw bad("not a rigid transform: holds a non-finite value");
  const Eigen::RowVector4d last(0, 0, 0, 1);
  if ((m.row(3) - last).cwiseAbs().maxCoeff() > kRigidTolerance) {
    throw bad("not a rigid transform: the last row is not [0, 0, 0, 1]");
  }
  const Mat3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Mat3d::Identity()).cwiseAbs().maxCoeff() > kRigidTolerance || R.determinant() < 0) {
    throw bad("not a rigid transform: the rotation block is not a rotation matrix");
  }
  return SE3::from_matrix(m);
}

}  // namespace farlio::io
