#pragma once
// Least-squares alignment of an estimated trajectory onto a reference.
//   umeyama_align: the rigid transform (optionally with a uniform scale, i.e. Sim(3)) that
//     minimises sum_k | target_k - (scale * R * source_k + t) |^2 over two point sets (Umeyama 1991).
//   align_poses: Umeyama on the positions of two pose sequences, except where the positions do not
//     determine the rotation (all on a line, or all at one point): the rotation the positions leave
//     free is then the one that best aligns the source orientations with the target ones.
//   align_origin: the rigid transform that makes the first source pose the first target pose
//     (evo's --align_origin): the errors are then the drift from the start, so that a trajectory
//     rotated as a whole (a map frame levelled a little off) has none, while a roll about a straight
//     path, which a least-squares fit of the positions leaves in the orientations, shows.
#include <Eigen/Core>
#include <span>

#include "farlio/core/se3.hpp"

namespace farlio::eval {

/// How an alignment's rotation was found.
enum class AlignmentMethod {
  kUmeyama,             ///< from the positions alone
  kUmeyamaOrientation,  ///< positions on a line: Umeyama, then the rotation about the line from the orientations
  kOrientation,         ///< positions at one point: the rotation from the orientations alone
  kOrigin,              ///< the first poses made one (align_origin)
};

/// Positions fix the rotation about an axis only when they spread across it: the spread (the square
/// root of a singular value of the position cross-covariance, m) must exceed this many times the RMS
/// residual of the Umeyama fit (m). A rotation error of a rad about the axis moves the points by
/// about a times the spread, so with a spread of a few residuals the positions hardly constrain it.
inline constexpr double kDefaultMinSpreadToResidual = 3.0;

struct Alignment {
  SE3 transform;       ///< R and t; maps source coordinates into the target frame
  double scale = 1.0;  ///< 1 unless a Sim(3) alignment was asked for
  /// True when the cross-covariance has rank < 2 (all points on a line, or fewer than 3
  /// distinct points): the rotation about that line is then not determined by the positions.
  bool rank_deficient = false;
  AlignmentMethod method = AlignmentMethod::kUmeyama;

  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& p) const {
    return scale * (transform.rotation() * p) + transform.translation();
  }
  /// A pose of the source frame expressed in the target frame (translation scaled, rotation not).
  [[nodiscard]] SE3 apply(const SE3& pose) const {
    return {transform.rotation() * pose.rotation(), apply(pose.translation())};
  }
};

/// Umeyama alignment of `source` onto `target` (same size, >= 1 point; throws InputError otherwise).
/// With collinear points the rotation about the line is one of the least-squares minimisers.
Alignment umeyama_align(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                        bool with_scale = false);

/// Alignment of the pose sequence `source` onto `target` (pairs by index; same size, >= 1 pose).
/// Umeyama on the positions (method kUmeyama) unless the second largest spread of the positions is
/// at most `min_spread_to_residual` times the RMS residual of that fit (or 1e-6 of the largest
/// spread): then the rotation about the principal axis maximises sum_k tr(R_target_k^T R R_source_k)
/// (kUmeyamaOrientation; for exactly collinear positions the position residuals are unchanged); if
/// even the largest spread is that small, the whole rotation does (kOrientation, scale 1). The
/// translation then takes the source centroid onto the target centroid.
Alignment align_poses(std::span<const SE3> source, std::span<const SE3> target, bool with_scale = false,
                      double min_spread_to_residual = kDefaultMinSpreadToResidual);

/// The transform target[0] source[0]^-1 (method kOrigin, scale 1); the sequences as align_poses.
Alignment align_origin(std::span<const SE3> source, std::span<const SE3> target);

}  // namespace farlio::eval
