#pragma once
// A smooth planar path through a polyline: straight legs joined by rounded corners whose
// curvature ramps up and down smoothly (C2 curvature, clothoid-like transitions). Arc length s
// parameterises the path; heading is the analytic integral of curvature and the position is
// the integral of the unit tangent by Gauss-Legendre quadrature on a fine table.
#include <Eigen/Core>
#include <vector>

#include "farlio/sim/smooth_curve.hpp"

namespace farlio::sim {

/// Where a corner's curvature is non-zero, and its peak curvature (1/radius).
struct PathCorner {
  double s_begin_m = 0.0;
  double s_end_m = 0.0;
  double peak_curvature_1_m = 0.0;  ///< unsigned
};

struct PathPoint {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double heading_rad = 0.0;
  double curvature_1_m = 0.0;  ///< signed, positive = left turn
  Eigen::Vector2d tangent = Eigen::Vector2d::UnitX();
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();  ///< tangent rotated +90 degrees
};

class Path {
 public:
  /// Open path from vertices.front() to vertices.back() with a corner at every interior vertex
  /// (corner_radii_m has vertices.size() - 2 entries), or, if closed, a loop with a corner at
  /// every vertex (corner_radii_m has vertices.size() entries) that starts and ends at the
  /// middle of the edge vertices[0] -> vertices[1]. corner_radii_m[i] rounds the vertex
  /// vertices[(i + 1) % n], i.e. corners are listed in travel order. Throws std::invalid_argument if two
  /// corners overlap (an edge too short for its rounded ends).
  static Path from_polyline(const std::vector<Eigen::Vector2d>& vertices, const std::vector<double>& corner_radii_m,
                            bool closed);

  /// The point at arc length s: wraps around for closed paths, extends straight past the
  /// ends of open ones.
  [[nodiscard]] PathPoint at(double s_m) const;
  [[nodiscard]] double length_m() const { return length_m_; }
  [[nodiscard]] bool closed() const { return closed_; }
  [[nodiscard]] const std::vector<PathCorner>& corners() const { return corners_; }

 private:
  [[nodiscard]] Eigen::Vector2d integrate_tangent(double s0_m, double s1_m) const;
  [[nodiscard]] double heading(double s_m) const { return heading0_rad_ + curvature_.integral(s_m); }

  SmoothCurve curvature_;  ///< curvature over arc length
  double heading0_rad_ = 0.0;
  Eigen::Vector2d origin_m_ = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> table_m_;  ///< positions at s = k * kTableStep_m
  std::vector<PathCorner> corners_;
  double length_m_ = 0.0;
  bool closed_ = false;
};

}  // namespace farlio::sim
