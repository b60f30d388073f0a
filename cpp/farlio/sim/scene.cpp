#include "farlio/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace farlio::sim {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kParallelEps = 1e-12;
}  // namespace

void Scene::build_index(double cell_size_m) {
  cell_m_ = cell_size_m;
  std::vector<Eigen::Vector4d> bounds;
  for (const auto& b : boxes_) bounds.push_back(b.bounds_xy());
  for (const auto& c : cylinders_) bounds.push_back(c.bounds_xy());
  if (bounds.empty()) {
    nx_ = ny_ = 0;
    return;
  }
  Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
  for (const auto& b : bounds) {
    lo = lo.cwiseMin(b.head<2>());
    hi = hi.cwiseMax(b.tail<2>());
  }
  grid_min_m_ = lo;
  nx_ = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell_m_)));
  ny_ = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell_m_)));
  auto cell_range = [&](const Eigen::Vector4d& b) {
    const int x0 = std::clamp(static_cast<int>((b[0] - lo.x()) / cell_m_), 0, nx_ - 1);
    const int y0 = std::clamp(static_cast<int>((b[1] - lo.y()) / cell_m_), 0, ny_ - 1);
    const int x1 = std::clamp(static_cast<int>((b[2] - lo.x()) / cell_m_), 0, nx_ - 1);
    const int y1 = std::clamp(static_cast<int>((b[3] - lo.y()) / cell_m_), 0, ny_ - 1);
    return Eigen::Vector4i(x0, y0, x1, y1);
  };
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) + 1, 0);
  for (const auto& b : bounds) {
    const Eigen::Vector4i r = cell_range(b);
    for (int y = r[1]; y <= r[3]; ++y)
      for (int x = r[0]; x <= r[2]; ++x)
        ++counts[static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x)];
  }
  cell_begin_.assign(counts.size(), 0);
  for (std::size_t c = 1; c < counts.size(); ++c) cell_begin_[c] = cell_begin_[c - 1] + counts[c - 1];
  cell_ids_.assign(cell_begin_.back(), 0);
  std::vector<std::uint32_t> fill(cell_begin_.begin(), cell_begin_.end() - 1);
  for (std::uint32_t id = 0; id < bounds.size(); ++id) {
    const Eigen::Vector4i r = cell_range(bounds[id]);
    for (int y = r[1]; y <= r[3]; ++y)
      for (int x = r[0]; x <= r[2]; ++x)
        cell_ids_[fill[static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x)]++] =
            id;
  }
}

std::optional<RayHit> Scene::intersect_primitive(std::uint32_t id, const Eigen::Vector3d& origin,
                                                 const Eigen::Vector3d& dir, double max_range_m) const {
  if (id < boxes_.size()) return boxes_[id].intersect(origin, dir, max_range_m);
  return cylinders_[id - boxes_.size()].intersect(origin, dir, max_range_m);
}

std::optional<RayHit> Scene::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range_m) const {
  std::optional<RayHit> best = ground_.intersect(origin, dir, max_range_m);
  if (ceiling_) {
    if (auto h = ceiling_->intersect(origin, dir, best ? best->range_m : max_range_m)) best = h;
  }
  if (nx_ == 0) return best;
  double limit = best ? best->range_m : max_range_m;

  // Clip the ray's horizontal projection to the grid rectangle.
  const Eigen::Vector2d o = origin.head<2>() - grid_min_m_;
  const Eigen::Vector2d d = dir.head<2>();
  const Eigen::Vector2d size(nx_ * cell_m_, ny_ * cell_m_);
  double t0 = 0.0, t1 = limit;
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < kParallelEps) {
      if (o[k] < 0.0 || o[k] > size[k]) return best;
      continue;
    }
    double a = -o[k] / d[k], b = (size[k] - o[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 > t1) return best;

  // 2-D DDA from the entry point.
  const Eigen::Vector2d p = o + t0 * d;
  int ix = std::clamp(static_cast<int>(p.x() / cell_m_), 0, nx_ - 1);
  int iy = std::clamp(static_cast<int>(p.y() / cell_m_), 0, ny_ - 1);
  const int step_x = d.x() >= 0.0 ? 1 : -1, step_y = d.y() >= 0.0 ? 1 : -1;
  auto next_boundary = [&](int i, int step, int axis) {
    if (std::abs(d[axis]) < kParallelEps) return kInf;
    return ((i + (step > 0 ? 1 : 0)) * cell_m_ - o[axis]) / d[axis];
  };
  double t_max_x = next_boundary(ix, step_x, 0), t_max_y = next_boundary(iy, step_y, 1);
  const double t_delta_x = std::abs(d.x()) < kParallelEps ? kInf : cell_m_ / std::abs(d.x());
  const double t_delta_y = std::abs(d.y()) < kParallelEps ? kInf : cell_m_ / std::abs(d.y());
  while (true) {
    const std::size_t c = static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(ix);
    for (std::uint32_t k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
      if (auto h = intersect_primitive(cell_ids_[k], origin, dir, limit)) {
        if (h->range_m < limit) {
          limit = h->range_m;
          best = h;
        }
      }
    }
    const double t_cell_exit = std::min(t_max_x, t_max_y);
    if (t_cell_exit >= limit || t_cell_exit > t1) break;
    if (t_max_x < t_max_y) {
      ix += step_x;
      t_max_x += t_delta_x;
      if (ix < 0 || ix >= nx_) break;
    } else {
      iy += step_y;
      t_max_y += t_delta_y;
      if (iy < 0 || iy >= ny_) break;
    }
  }
  return best;
}

double Scene::surface_distance_m(const Eigen::Vector3d& p) const {
  double d = std::abs(p.z() - ground_.height_m(p.x()));
  if (ceiling_) d = std::min(d, std::abs(p.z() - ceiling_->z_m));
  for (const Box& b : boxes_) d = std::min(d, b.surface_distance_m(p));
  for (const Cylinder& c : cylinders_) d = std::min(d, c.surface_distance_m(p));
  return d;
}

}  // namespace farlio::sim
