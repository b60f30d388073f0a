#pragma once
// A 4x4 matrix read from a file (calib.yaml, KITTI calibration text) checked to be a rigid
// transform before it becomes an SE3.
#include <string>

#include "farlio/core/se3.hpp"

namespace farlio::io {

/// How far a matrix may be from rigid: max deviation of R^T R from I and of the last row from [0 0 0 1].
inline constexpr double kRigidTolerance = 1e-4;

/// The SE3 of `m` if it is a rigid transform within kRigidTolerance (finite values, last row
/// [0 0 0 1], rotation block orthonormal with determinant +1); otherwise InputError
/// "<what>: <why>", so `what` should name the file and the key.
[[nodiscard]] SE3 rigid_transform_from_matrix(const Mat4d& m, const std::string& what);

}  // namespace farlio::io
