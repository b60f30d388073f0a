#pragma once
// Analytic scene primitives and their exact ray intersections. A ray is origin + r * dir with
// a unit dir; each intersect() returns the smallest r in (0, max_range_m] or nothing.
#include <Eigen/Core>
#include <optional>
#include <vector>

namespace farlio::sim {

struct RayHit {
  double range_m = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit surface normal (either side)
  float reflectivity = 0.0F;                          ///< in [0, 1]
};

/// A box with vertical sides rotated by yaw about the vertical axis (buildings, walls,
/// barriers, parked cars, thin fences). With a slope its top and bottom are inclined along its
/// own x (a ramp): in the box frame they are z = slope * x +- half_extent_m.z.
struct Box {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_extent_m = Eigen::Vector3d::Ones();  ///< along the box's own x, y, z
  double yaw_rad = 0.0;
  float reflectivity = 0.5F;
  double slope = 0.0;  ///< rise of the top and bottom per metre along the box's x (0: level)

  [[nodiscard]] std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                                double max_range_m) const;
  /// Horizontal bounding rectangle (min x, min y, max x, max y).
  [[nodiscard]] Eigen::Vector4d bounds_xy() const;
  /// Distance from p to the box's surface (from inside or outside; with a slope, within a
  /// factor 1 + slope^2 of it near the inclined faces' edges).
  [[nodiscard]] double surface_distance_m(const Eigen::Vector3d& p) const;
};

/// A vertical solid cylinder with flat caps (poles, tree trunks and crowns, pillars).
struct Cylinder {
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();
  double radius_m = 0.1;
  double z_min_m = 0.0;
  double z_max_m = 1.0;
  float reflectivity = 0.5F;

  [[nodiscard]] std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                                double max_range_m) const;
  [[nodiscard]] Eigen::Vector4d bounds_xy() const;
  /// Distance from p to the cylinder's surface, caps included (from inside or outside).
  [[nodiscard]] double surface_distance_m(const Eigen::Vector3d& p) const;
};

/// Ground z = h(x), piecewise linear through knots (constant beyond the ends), infinite in y.
/// A single knot gives a flat ground.
class GroundProfile {
 public:
  GroundProfile() = default;
  GroundProfile(std::vector<double> x_m, std::vector<double> z_m, float reflectivity);
  [[nodiscard]] double height_m(double x_m) const;
  [[nodiscard]] std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                                double max_range_m) const;

 private:
  std::vector<double> x_m_, z_m_;
  float reflectivity_ = 0.3F;
};

/// The horizontal plane z = height from below (a ceiling).
struct Ceiling {
  double z_m = 0.0;
  float reflectivity = 0.6F;
  [[nodiscard]] std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                                double max_range_m) const;
};

}  // namespace farlio::sim
