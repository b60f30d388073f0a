#pragma once
// A scene of analytic primitives with a uniform 2-D grid over their horizontal bounding
// rectangles: a ray visits only the cells its horizontal projection crosses (2-D DDA) and
// stops at the first cell that ends beyond its nearest hit.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "farlio/sim/primitives.hpp"

namespace farlio::sim {

class Scene {
 public:
  void set_ground(GroundProfile ground) { ground_ = std::move(ground); }
  void set_ceiling(Ceiling ceiling) { ceiling_ = ceiling; }
  void add(const Box& box) { boxes_.push_back(box); }
  void add(const Cylinder& cylinder) { cylinders_.push_back(cylinder); }

  /// Builds the grid; call after the last add() and before cast().
  void build_index(double cell_size_m);

  /// Nearest hit of the ray origin + r * dir (dir unit) with r in (0, max_range_m].
  [[nodiscard]] std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                           double max_range_m) const;

  /// Distance from p to the nearest surface (ground, ceiling, boxes, cylinders; the ground's
  /// vertical distance, exact on level ground). Brute force over the primitives: for tests.
  [[nodiscard]] double surface_distance_m(const Eigen::Vector3d& p) const;

  [[nodiscard]] std::size_t num_primitives() const { return boxes_.size() + cylinders_.size(); }
  [[nodiscard]] const std::vector<Box>& boxes() const { return boxes_; }
  [[nodiscard]] const std::vector<Cylinder>& cylinders() const { return cylinders_; }
  [[nodiscard]] const GroundProfile& ground() const { return ground_; }

 private:
  [[nodiscard]] std::optional<RayHit> intersect_primitive(std::uint32_t id, const Eigen::Vector3d& origin,
                                                          const Eigen::Vector3d& dir, double max_range_m) const;

  GroundProfile ground_{{0.0}, {0.0}, 0.3F};
  std::optional<Ceiling> ceiling_;
  std::vector<Box> boxes_;
  std::vector<Cylinder> cylinders_;
  // Grid: cell (ix, iy) holds ids cell_ids_[cell_begin_[c] .. cell_begin_[c + 1]); an id below
  // boxes_.size() is a box, the rest are cylinders.
  Eigen::Vector2d grid_min_m_ = Eigen::Vector2d::Zero();
  double cell_m_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> cell_begin_;
  std::vector<std::uint32_t> cell_ids_;
};

}  // namespace farlio::sim
