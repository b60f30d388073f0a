#include "farlio/sim/primitives.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace farlio::sim {
namespace {
/// Rays starting this close to a surface do not hit it (avoids self-intersection).
constexpr double kMinRange_m = 1e-6;
constexpr double kParallelEps = 1e-12;
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

std::optional<RayHit> Box::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                     double max_range_m) const {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const Eigen::Vector3d o = origin - center_m;
  // Into the box frame: rotate by -yaw, and shear z by the slope so the inclined faces are level.
  const double ox = c * o.x() + s * o.y(), dx = c * dir.x() + s * dir.y();
  const Eigen::Vector3d lo(ox, -s * o.x() + c * o.y(), o.z() - slope * ox);
  const Eigen::Vector3d ld(dx, -s * dir.x() + c * dir.y(), dir.z() - slope * dx);
  double t_near = -kInf, t_far = kInf;
  int axis = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(ld[k]) < kParallelEps) {
      if (std::abs(lo[k]) > half_extent_m[k]) return std::nullopt;
      continue;
    }
    const double inv = 1.0 / ld[k];
    double t0 = (-half_extent_m[k] - lo[k]) * inv, t1 = (half_extent_m[k] - lo[k]) * inv;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      axis = k;
    }
    t_far = std::min(t_far, t1);
    if (t_near > t_far) return std::nullopt;
  }
  if (t_near < kMinRange_m || t_near > max_range_m) return std::nullopt;
  Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
  n_local[axis] = 1.0;
  if (axis == 2) n_local = Eigen::Vector3d(-slope, 0.0, 1.0).normalized();
  return RayHit{t_near,
                Eigen::Vector3d(c * n_local.x() - s * n_local.y(), s * n_local.x() + c * n_local.y(), n_local.z()),
                reflectivity};
}

Eigen::Vector4d Box::bounds_xy() const {
  const double c = std::abs(std::cos(yaw_rad)), s = std::abs(std::sin(yaw_rad));
  const double ex = c * half_extent_m.x() + s * half_extent_m.y();
  const double ey = s * half_extent_m.x() + c * half_extent_m.y();
  return {center_m.x() - ex, center_m.y() - ey, center_m.x() + ex, center_m.y() + ey};
}

std::optional<RayHit> Cylinder::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                          double max_range_m) const {
  std::optional<RayHit> best;
  const Eigen::Vector2d o = origin.head<2>() - center_m;
  const Eigen::Vector2d d = dir.head<2>();
  const double a = d.squaredNorm();
  if (a > kParallelEps) {  // the side
    const double b = o.dot(d), c = o.squaredNorm() - radius_m * radius_m;
    const double disc = b * b - a * c;
    if (disc >= 0.0) {
      const double t = (-b - std::sqrt(disc)) / a;
      const double z = origin.z() + t * dir.z();
      if (t >= kMinRange_m && t <= max_range_m && z >= z_min_m && z <= z_max_m) {
        const Eigen::Vector2d n = (o + t * d) / radius_m;
        best = RayHit{t, Eigen::Vector3d(n.x(), n.y(), 0.0), reflectivity};
      }
    }
  }
  if (std::abs(dir.z()) > kParallelEps) {  // the caps
    for (const double zc : {z_min_m, z_max_m}) {
      const double t = (zc - origin.z()) / dir.z();
      if (t < kMinRange_m || t > max_range_m || (best && t >= best->range_m)) continue;
      if ((o + t * d).squaredNorm() <= radius_m * radius_m) best = RayHit{t, Eigen::Vector3d::UnitZ(), reflectivity};
    }
  }
  return best;
}

namespace {
/// Distance to the surface of the region where every component of `excess` (the signed distance
/// beyond each pair of faces) is <= 0.
template <typename Vec>
double surface_distance(const Vec& excess) {
  const double outside = excess.cwiseMax(0.0).norm();
  return outside > 0.0 ? outside : -excess.maxCoeff();
}
}  // namespace

double Box::surface_distance_m(const Eigen::Vector3d& p) const {
  Eigen::Vector3d local = Eigen::AngleAxisd(-yaw_rad, Eigen::Vector3d::UnitZ()) * (p - center_m);
  // The inclined faces: the sheared height over the face's normal length is the distance to its plane.
  const double incline = std::sqrt(1.0 + slope * slope);
  local.z() = (local.z() - slope * local.x()) / incline;
  return surface_distance(Eigen::Vector3d(
      local.cwiseAbs() - Eigen::Vector3d(half_extent_m.x(), half_extent_m.y(), half_extent_m.z() / incline)));
}

double Cylinder::surface_distance_m(const Eigen::Vector3d& p) const {
  const double radial = (p.head<2>() - center_m).norm() - radius_m;
  const double vertical = std::max(z_min_m - p.z(), p.z() - z_max_m);
  return surface_distance(Eigen::Vector2d(radial, vertical));
}

Eigen::Vector4d Cylinder::bounds_xy() const {
  return {center_m.x() - radius_m, center_m.y() - radius_m, center_m.x() + radius_m, center_m.y() + radius_m};
}

GroundProfile::GroundProfile(std::vector<double> x_m, std::vector<double> z_m, float reflectivity)
    : x_m_(std::move(x_m)), z_m_(std::move(z_m)), reflectivity_(reflectivity) {
  if (x_m_.empty() || x_m_.size() != z_m_.size() || !std::is_sorted(x_m_.begin(), x_m_.end()))
    throw std::invalid_argument("GroundProfile: need sorted knots with one height each");
}

double GroundProfile::height_m(double x_m) const {
  if (x_m <= x_m_.front()) return z_m_.front();
  if (x_m >= x_m_.back()) return z_m_.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(x_m_.begin(), x_m_.end(), x_m) - x_m_.begin()) - 1;
  const double u = (x_m - x_m_[k]) / (x_m_[k + 1] - x_m_[k]);
  return z_m_[k] + u * (z_m_[k + 1] - z_m_[k]);
}

std::optional<RayHit> GroundProfile::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                               double max_range_m) const {
  // Walk the linear pieces in the order the ray crosses them. Piece k spans
  // [x_{k-1}, x_k] (piece 0 and piece n extend to -inf and +inf at constant height).
  const std::size_t n = x_m_.size();
  auto piece_of = [&](double x) {
    return static_cast<std::size_t>(std::upper_bound(x_m_.begin(), x_m_.end(), x) - x_m_.begin());
  };
  std::size_t k = piece_of(origin.x());
  const bool forward = dir.x() >= 0.0;
  double t_enter = 0.0;
  while (t_enter <= max_range_m) {
    const double xa = k == 0 ? -kInf : x_m_[k - 1], xb = k == n ? kInf : x_m_[k];
    const double za = k == 0 ? z_m_.front() : z_m_[k - 1];
    const double slope = (k == 0 || k == n) ? 0.0 : (z_m_[k] - z_m_[k - 1]) / (xb - xa);
    const double x_ref = k == 0 ? x_m_.front() : xa;
    double t_exit = kInf;
    if (std::abs(dir.x()) > kParallelEps) t_exit = ((forward ? xb : xa) - origin.x()) / dir.x();
    // (oz + t dz) = za + slope * (ox + t dx - x_ref)
    const double denom = dir.z() - slope * dir.x();
    if (std::abs(denom) > kParallelEps) {
      const double t = (za + slope * (origin.x() - x_ref) - origin.z()) / denom;
      if (t >= std::max(t_enter, kMinRange_m) && t <= std::min(t_exit, max_range_m)) {
        const Eigen::Vector3d normal = Eigen::Vector3d(-slope, 0.0, 1.0).normalized();
        return RayHit{t, normal, reflectivity_};
      }
    }
    if (t_exit == kInf) break;
    t_enter = t_exit;
    if (forward) {
      if (k == n) break;
      ++k;
    } else {
      if (k == 0) break;
      --k;
    }
  }
  return std::nullopt;
}

std::optional<RayHit> Ceiling::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                         double max_range_m) const {
  if (dir.z() <= kParallelEps) return std::nullopt;
  const double t = (z_m - origin.z()) / dir.z();
  if (t < kMinRange_m || t > max_range_m) return std::nullopt;
  return RayHit{t, Eigen::Vector3d::UnitZ(), reflectivity};
}

}  // namespace farlio::sim
