#include "farlio/sim/path.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace farlio::sim {
namespace {
constexpr double kTableStep_m = 0.5;
/// Share of a corner's arc spent ramping curvature up (and again down).
constexpr double kTransitionFraction = 0.5;
constexpr double kMinStraight_m = 1e-9;
constexpr double kClosureTolerance_m = 1e-6;
// 5-point Gauss-Legendre rule on [-1, 1].
constexpr std::array<double, 5> kGaussNodes = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                               0.9061798459386640};
constexpr std::array<double, 5> kGaussWeights = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                                 0.4786286704993665, 0.2369268850561891};

struct TurnShape {
  double transition_m, hold_m, curvature_1_m;
  [[nodiscard]] double length_m() const { return 2.0 * transition_m + hold_m; }
};

TurnShape turn_shape(double angle_rad, double radius_m) {
  const double arc_m = std::abs(angle_rad) * radius_m;
  const double transition_m = kTransitionFraction * arc_m;
  return {transition_m, arc_m - transition_m, std::copysign(1.0 / radius_m, angle_rad)};
}

double wrap_angle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

/// Distance from a corner's start (and from its end) to the polyline vertex it rounds.
double tangent_distance_m(const TurnShape& shape, double angle_rad) {
  SmoothCurve k({0.0, shape.transition_m, shape.transition_m + shape.hold_m, shape.length_m()},
                {0.0, shape.curvature_1_m, shape.curvature_1_m, 0.0});
  constexpr int kSteps = 400;
  const double h = shape.length_m() / kSteps;
  Eigen::Vector2d end = Eigen::Vector2d::Zero();
  for (int i = 0; i < kSteps; ++i) {
    for (std::size_t g = 0; g < kGaussNodes.size(); ++g) {
      const double s = h * (i + 0.5 + 0.5 * kGaussNodes[g]);
      const double psi = k.integral(s);
      end += 0.5 * h * kGaussWeights[g] * Eigen::Vector2d(std::cos(psi), std::sin(psi));
    }
  }
  // The entry line (x axis) and exit line meet at the vertex: end - d * exit_dir = (d, 0).
  return end.y() / std::sin(angle_rad);
}
}  // namespace

Path Path::from_polyline(const std::vector<Eigen::Vector2d>& vertices, const std::vector<double>& corner_radii_m,
                         bool closed) {
  const std::size_t n = vertices.size();
  const std::size_t num_corners = closed ? n : n - 2;
  if (n < (closed ? 3U : 2U) || corner_radii_m.size() != num_corners)
    throw std::invalid_argument("Path: need one corner radius per corner vertex");
  // Legs in travel order: start point, the corner vertices, end point.
  std::vector<Eigen::Vector2d> pts;
  if (closed) {
    pts.push_back(0.5 * (vertices[0] + vertices[1]));
    for (std::size_t i = 1; i <= n; ++i) pts.push_back(vertices[i % n]);
    pts.push_back(pts.front());
  } else {
    pts = vertices;
  }
  Path path;
  path.closed_ = closed;
  path.origin_m_ = pts.front();
  const Eigen::Vector2d first_dir = (pts[1] - pts[0]).normalized();
  path.heading0_rad_ = std::atan2(first_dir.y(), first_dir.x());

  std::vector<double> ks{0.0}, kv{0.0};
  double s = 0.0;
  double pending_m = 0.0;  // tangent distance of the previous corner, eaten from this leg
  for (std::size_t c = 0; c + 2 < pts.size() + 1; ++c) {
    const bool has_corner = c + 2 < pts.size();
    const Eigen::Vector2d leg = pts[c + 1] - pts[c];
    double straight_m = leg.norm() - pending_m;
    TurnShape shape{};
    double d_m = 0.0;
    double angle = 0.0;
    if (has_corner) {
      const Eigen::Vector2d next = pts[c + 2] - pts[c + 1];
      angle = wrap_angle(std::atan2(next.y(), next.x()) - std::atan2(leg.y(), leg.x()));
      shape = turn_shape(angle, corner_radii_m[c]);
      d_m = tangent_distance_m(shape, angle);
      straight_m -= d_m;
    }
    if (straight_m < -kMinStraight_m)
      throw std::invalid_argument("Path: leg " + std::to_string(c) + " is too short for its rounded corners");
    if (straight_m > kMinStraight_m) {
      s += straight_m;
      ks.push_back(s);
      kv.push_back(0.0);
    }
    if (has_corner) {
      path.corners_.push_back({s, s + shape.length_m(), std::abs(shape.curvature_1_m)});
      ks.insert(ks.end(), {s + shape.transition_m, s + shape.transition_m + shape.hold_m, s + shape.length_m()});
      kv.insert(kv.end(), {shape.curvature_1_m, shape.curvature_1_m, 0.0});
      s += shape.length_m();
      pending_m = d_m;
    }
  }
  path.length_m_ = s;
  path.curvature_ = SmoothCurve(ks, kv);
  const auto steps = static_cast<std::size_t>(std::ceil(s / kTableStep_m));
  path.table_m_.reserve(steps + 1);
  path.table_m_.push_back(path.origin_m_);
  for (std::size_t i = 0; i < steps; ++i) {
    const double s0 = static_cast<double>(i) * kTableStep_m;
    path.table_m_.push_back(path.table_m_.back() + path.integrate_tangent(s0, s0 + kTableStep_m));
  }
  if (closed && (path.at(path.length_m_ - 1e-12).position_m - path.origin_m_).norm() > kClosureTolerance_m)
    throw std::logic_error("Path: closed polyline does not close");
  return path;
}

Eigen::Vector2d Path::integrate_tangent(double s0_m, double s1_m) const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  const double half = 0.5 * (s1_m - s0_m), mid = 0.5 * (s1_m + s0_m);
  for (std::size_t g = 0; g < kGaussNodes.size(); ++g) {
    const double psi = heading(mid + half * kGaussNodes[g]);
    sum += kGaussWeights[g] * Eigen::Vector2d(std::cos(psi), std::sin(psi));
  }
  return half * sum;
}

PathPoint Path::at(double s_m) const {
  if (closed_) s_m -= length_m_ * std::floor(s_m / length_m_);
  PathPoint p;
  p.heading_rad = heading(s_m);
  p.curvature_1_m = curvature_.value(s_m);
  p.tangent = {std::cos(p.heading_rad), std::sin(p.heading_rad)};
  p.normal = {-p.tangent.y(), p.tangent.x()};
  const double table_end_m = static_cast<double>(table_m_.size() - 1) * kTableStep_m;
  if (s_m <= 0.0) {
    p.position_m = origin_m_ + s_m * p.tangent;
  } else if (s_m >= table_end_m) {
    p.position_m = table_m_.back() + (s_m - table_end_m) * p.tangent;
  } else {
    const auto k = static_cast<std::size_t>(s_m / kTableStep_m);
    const double s0 = static_cast<double>(k) * kTableStep_m;
    p.position_m = table_m_[k] + integrate_tangent(s0, s_m);
  }
  return p;
}

}  // namespace farlio::sim
