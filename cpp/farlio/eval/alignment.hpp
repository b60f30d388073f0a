#pragma once
// Least-squares alignment of two corresponding point sets (Umeyama 1991): the rigid transform
// (optionally with a uniform scale, i.e. Sim(3)) that minimises
//   sum_k | target_k - (scale * R * source_k + t) |^2 .
#include <Eigen/Core>
#include <span>

#include "farlio/core/se3.hpp"

namespace farlio::eval {

struct Alignment {
  SE3 transform;       ///< R and t; maps source coordinates into the target frame
  double scale = 1.0;  ///< 1 unless a Sim(3) alignment was asked for
  /// True when the cross-covariance has rank < 2 (all points on a line, or fewer than 3
  /// distinct points): the rotation about that line is then not determined; the transform
  /// returned is still one of the least-squares minimisers.
  bool rank_deficient = false;

  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& p) const {
    return scale * (transform.rotation() * p) + transform.translation();
  }
  /// A pose of the source frame expressed in the target frame (translation scaled, rotation not).
  [[nodiscard]] SE3 apply(const SE3& pose) const {
    return {transform.rotation() * pose.rotation(), apply(pose.translation())};
  }
};

/// Umeyama alignment of `source` onto `target` (same size, >= 1 point; throws InputError otherwise).
Alignment umeyama_align(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                        bool with_scale = false);

}  // namespace farlio::eval
