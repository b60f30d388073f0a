// The handheld profile: a person walks with a hand-held 32-beam LiDAR through a furnished
// room, a 60 m long featureless corridor (a degenerate case for registration: long uniform
// walls) and a second room with pillars, stopping three times to look around quickly, then back
// through the corridor into the first room.
#include <cmath>
#include <numbers>

#include "farlio/sim/world.hpp"

namespace farlio::sim {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kCeiling_m = 2.8, kWallHeight_m = 3.0, kWallThickness_m = 0.2;

// Walking.
constexpr double kWalkSpeed_m_s = 1.4, kMaxLateralAccel_m_s2 = 1.0, kMaxLongitudinalAccel_m_s2 = 0.8;
constexpr double kInitialRest_s = 2.0, kStopHold_s = 4.4, kTurnRadius_m = 0.5;
constexpr WalkStyle kStyle{1.5, 0.7, 0.025, 0.02, 0.03};
// Look-around during every stop: yaw +kLookLeft, back, -kLookRight, back.
constexpr double kLookLeft_rad = 1.2, kLookRight_rad = 1.0, kLookTurn_s = 0.8, kLookPause_s = 0.3;
constexpr double kLookLead_s = 0.2;

// Sensor: 32 beams from -16 to +15 degrees, 1800 azimuth steps.
constexpr std::size_t kChannels = 32;
constexpr double kLowestElevation_rad = -16.0 * kDeg, kHighestElevation_rad = 15.0 * kDeg;
constexpr int kColumns = 1800;
constexpr double kMinRange_m = 0.3, kMaxRange_m = 60.0, kGridCell_m = 2.0;

/// An axis-aligned wall from (x0, y0) to (x1, y1) (one of them constant).
void wall(Scene& scene, double x0, double y0, double x1, double y1) {
  const double lx = std::abs(x1 - x0) + kWallThickness_m, ly = std::abs(y1 - y0) + kWallThickness_m;
  scene.add(Box{Eigen::Vector3d(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * kWallHeight_m),
                Eigen::Vector3d(0.5 * lx, 0.5 * ly, 0.5 * kWallHeight_m), 0.0, 0.6F});
}

/// Furniture standing on the floor: centre (x, y), size (sx, sy, height).
void furniture(Scene& scene, double x, double y, double sx, double sy, double h, float reflectivity) {
  scene.add(Box{Eigen::Vector3d(x, y, 0.5 * h), Eigen::Vector3d(0.5 * sx, 0.5 * sy, 0.5 * h), 0.0, reflectivity});
}

void build_floor_plan(Scene& scene) {
  // Room A [0, 10] x [0, 8], open on its east side into the corridor (y in [3, 5]).
  wall(scene, 0, 0, 10, 0);
  wall(scene, 0, 8, 10, 8);
  wall(scene, 0, 0, 0, 8);
  wall(scene, 10, 0, 10, 3);
  wall(scene, 10, 5, 10, 8);
  furniture(scene, 4.5, 5.2, 1.4, 0.7, 0.75, 0.5F);  // table
  furniture(scene, 6.0, 7.7, 2.0, 0.4, 2.0, 0.7F);   // cabinet
  furniture(scene, 3.0, 0.25, 1.5, 0.3, 1.8, 0.4F);  // shelf
  furniture(scene, 9.5, 6.5, 0.8, 1.6, 0.9, 0.3F);   // sofa end
  scene.add(Cylinder{{5.0, 2.8}, 0.25, 0.0, kCeiling_m, 0.6F});
  // The corridor: 60 m of plain, parallel walls.
  wall(scene, 10, 3, 70, 3);
  wall(scene, 10, 5, 70, 5);
  // Room B [70, 84] x [-4, 12], open on its west side into the corridor.
  wall(scene, 70, -4, 70, 3);
  wall(scene, 70, 5, 70, 12);
  wall(scene, 84, -4, 84, 12);
  wall(scene, 70, -4, 84, -4);
  wall(scene, 70, 12, 84, 12);
  for (const double x : {74.0, 80.0})
    for (const double y : {0.0, 8.0}) scene.add(Cylinder{{x, y}, 0.3, 0.0, kCeiling_m, 0.6F});
  furniture(scene, 75.5, 11.3, 2.0, 0.8, 0.75, 0.5F);
  furniture(scene, 83.4, 4.0, 0.8, 3.0, 1.2, 0.8F);
  furniture(scene, 77.0, -3.5, 3.0, 0.6, 2.2, 0.4F);
}

SmoothCurve look_around(const std::vector<std::pair<double, double>>& stops) {
  SmoothCurve yaw({0.0}, {0.0});
  for (const auto& [begin, end] : stops) {
    double t = begin + kLookLead_s;
    yaw.add_knot(t, 0.0);
    for (const double target : {kLookLeft_rad, -kLookRight_rad}) {
      yaw.add_knot(t += kLookTurn_s, target);
      yaw.add_knot(t += kLookPause_s, target);
      yaw.add_knot(t += kLookTurn_s, 0.0);
    }
    (void)end;
  }
  return yaw;
}
}  // namespace

World build_handheld_world() {
  // After room B the walk returns through the corridor into room A (~125 s in, for loop closure).
  const std::vector<Eigen::Vector2d> route = {{2, 1.5}, {8, 1.5}, {8, 6.5}, {2, 6.5}, {2, 4}, {77, 4}, {77, 10},
                                              {82, 10}, {82, -2}, {72, -2}, {72, 4},  {5, 4}, {5, 2}};
  Path path = Path::from_polyline(route, std::vector<double>(route.size() - 2, kTurnRadius_m), false);
  SpeedPlan plan(path, {kWalkSpeed_m_s, kMaxLateralAccel_m_s2, kMaxLongitudinalAccel_m_s2, kInitialRest_s},
                 {{0, kStopHold_s}, {4, kStopHold_s}, {7, kStopHold_s}});
  SmoothCurve yaw_offset = look_around(plan.stop_intervals_s());

  World w;
  build_floor_plan(w.scene);
  w.scene.set_ceiling(Ceiling{kCeiling_m, 0.6F});
  w.scene.build_index(kGridCell_m);
  w.facts["route_length_m"] = std::to_string(path.length_m());
  w.facts["lidar"] = "32-beam spinning LiDAR, -16..+15 deg, 1800 azimuth steps";
  w.facts["degenerate_segment"] = "corridor x in [10, 70] m, y in [3, 5] m";
  w.motion = std::make_shared<WalkerMotion>(std::move(path), std::move(plan), std::move(yaw_offset), kStyle);
  w.T_imu_lidar = mount_pose({0.05, 0.0, 0.12}, 0.02, -0.01, 0.015);
  w.lidars.push_back(spinning_lidar(0, SE3::identity(),
                                    uniform_elevations_rad(kChannels, kLowestElevation_rad, kHighestElevation_rad),
                                    kColumns, kMinRange_m, kMaxRange_m));
  return w;
}

}  // namespace farlio::sim
