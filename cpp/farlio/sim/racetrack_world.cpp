// The racetrack profile: a ~4 km closed circuit driven at up to 70 m/s from a standing start
// (at rest for 2 s, then accelerating down the start straight), lined with concrete
// barriers, catch fences with gaps, posts, marshal boards, grandstands and a pit building;
// three 120-degree raster LiDARs (front, left, right) merged into one frame.
#include <cmath>
#include <numbers>
#include <string>

#include "farlio/sim/random.hpp"
#include "farlio/sim/world.hpp"

namespace farlio::sim {
namespace {
constexpr std::uint64_t kLayoutSeed = 0x7261636574726B31ULL;
constexpr double kDeg = std::numbers::pi / 180.0;

// Circuit and driving.
constexpr double kMaxSpeed_m_s = 70.0;
constexpr double kMaxLateralAccel_m_s2 = 24.0;
constexpr double kMaxLongitudinalAccel_m_s2 = 15.0;
constexpr double kInitialRest_s = 2.0;  // standing start: a LiDAR-inertial odometry cannot know an initial speed
constexpr double kBodyHeight_m = 0.5;
// Trackside (lateral offsets from the centre line).
constexpr double kBarrierOffset_m = 7.0, kBarrierHeight_m = 1.0, kBarrierThickness_m = 0.6, kBarrierStep_m = 5.0;
constexpr double kFenceOffset_m = 10.5, kFenceHeight_m = 3.5, kFenceThickness_m = 0.05, kFenceStep_m = 8.0;
constexpr double kFenceGapChance = 0.12;
constexpr double kPostOffset_m = 8.8, kPostSpacingMin_m = 20.0, kPostSpacingMax_m = 60.0;
constexpr double kPostRadiusMin_m = 0.12, kPostRadiusMax_m = 0.3, kPostHeightMin_m = 4.0, kPostHeightMax_m = 8.0;
constexpr double kBoardSpacingMin_m = 60.0, kBoardSpacingMax_m = 180.0;
constexpr double kBoardHeightMin_m = 1.5, kBoardHeightMax_m = 3.0, kBoardHalfWidthMin_m = 0.5,
                 kBoardHalfWidthMax_m = 1.5;
constexpr double kBoardHalfDepth_m = 0.4, kBoardYawJitter_rad = 0.3;
constexpr double kTrunkRadius_m = 0.25, kTrunkHeight_m = 3.0, kCrownRadiusMin_m = 1.5, kCrownRadiusMax_m = 3.0;
constexpr double kCrownTopMin_m = 6.0, kCrownTopMax_m = 12.0;
constexpr float kBarrierReflectivity = 0.5F, kFenceReflectivity = 0.25F, kPostReflectivity = 0.7F;
constexpr float kBoardReflectivity = 0.9F, kTrunkReflectivity = 0.4F, kCrownReflectivity = 0.35F;
constexpr double kTreeOffsetMin_m = 14.0, kTreeOffsetMax_m = 40.0, kTreeSpacing_m = 25.0, kTreeChance = 0.5;
constexpr double kSegmentOverlap_m = 0.05;
// Sensors.
constexpr std::size_t kChannels = 128;
constexpr double kLowestElevation_rad = -20.0 * kDeg, kHighestElevation_rad = 6.0 * kDeg;
constexpr int kColumns = 570;
constexpr double kFov_rad = 120.0 * kDeg;
constexpr double kMinRange_m = 0.5, kMaxRange_m = 200.0;
constexpr double kGridCell_m = 10.0;

void add_segment_box(Scene& scene, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double height,
                     double thickness, float reflectivity) {
  const Eigen::Vector2d d = b - a;
  const Eigen::Vector2d c = 0.5 * (a + b);
  scene.add(Box{Eigen::Vector3d(c.x(), c.y(), z0 + 0.5 * height),
                Eigen::Vector3d(0.5 * d.norm() + kSegmentOverlap_m, 0.5 * thickness, 0.5 * height),
                std::atan2(d.y(), d.x()), reflectivity});
}

/// A wall following the path at a signed lateral offset, as chords of step_m.
void add_wall_along(Scene& scene, const Path& path, double offset_m, double step_m, double height_m, double thickness_m,
                    float reflectivity, double gap_chance, Rng& rng) {
  const int n = static_cast<int>(std::ceil(path.length_m() / step_m));
  for (int i = 0; i < n; ++i) {
    const double s0 = path.length_m() * i / n, s1 = path.length_m() * (i + 1) / n;
    if (gap_chance > 0.0 && rng.chance(gap_chance)) continue;
    const PathPoint p0 = path.at(s0), p1 = path.at(s1);
    add_segment_box(scene, p0.position_m + offset_m * p0.normal, p1.position_m + offset_m * p1.normal, 0.0, height_m,
                    thickness_m, reflectivity);
  }
}

/// True if c is farther than kTreeOffsetMin_m from every part of the centre line.
bool clear_of_track(const Path& path, const Eigen::Vector2d& c) {
  for (double s = 0.0; s < path.length_m(); s += kBarrierStep_m)
    if ((path.at(s).position_m - c).norm() < kTreeOffsetMin_m) return false;
  return true;
}

void add_trackside_objects(Scene& scene, const Path& path, Rng& rng) {
  for (const double side : {-1.0, 1.0}) {
    for (double s = rng.uniform(0.0, kPostSpacingMax_m); s < path.length_m();
         s += rng.uniform(kPostSpacingMin_m, kPostSpacingMax_m)) {
      const PathPoint p = path.at(s);
      const Eigen::Vector2d c = p.position_m + side * kPostOffset_m * p.normal;
      scene.add(Cylinder{c, rng.uniform(kPostRadiusMin_m, kPostRadiusMax_m), 0.0,
                         rng.uniform(kPostHeightMin_m, kPostHeightMax_m), kPostReflectivity});
    }
    for (double s = rng.uniform(0.0, kBoardSpacingMax_m); s < path.length_m();
         s += rng.uniform(kBoardSpacingMin_m, kBoardSpacingMax_m)) {
      const PathPoint p = path.at(s);
      const Eigen::Vector2d c = p.position_m + side * kPostOffset_m * p.normal;
      const double h = rng.uniform(kBoardHeightMin_m, kBoardHeightMax_m);
      scene.add(
          Box{Eigen::Vector3d(c.x(), c.y(), 0.5 * h),
              Eigen::Vector3d(rng.uniform(kBoardHalfWidthMin_m, kBoardHalfWidthMax_m), kBoardHalfDepth_m, 0.5 * h),
              p.heading_rad + rng.uniform(-kBoardYawJitter_rad, kBoardYawJitter_rad), kBoardReflectivity});
    }
    for (double s = 0.0; s < path.length_m(); s += kTreeSpacing_m) {
      if (!rng.chance(kTreeChance)) continue;
      const PathPoint p = path.at(s + rng.uniform(0.0, kTreeSpacing_m));
      const Eigen::Vector2d c = p.position_m + side * rng.uniform(kTreeOffsetMin_m, kTreeOffsetMax_m) * p.normal;
      if (!clear_of_track(path, c)) continue;  // another part of the circuit may pass nearby
      scene.add(Cylinder{c, kTrunkRadius_m, 0.0, kTrunkHeight_m, kTrunkReflectivity});
      scene.add(Cylinder{c, rng.uniform(kCrownRadiusMin_m, kCrownRadiusMax_m), kTrunkHeight_m,
                         rng.uniform(kCrownTopMin_m, kCrownTopMax_m), kCrownReflectivity});
    }
  }
}

/// Stepped grandstands on the outside of the main straight (y < 0) and a pit building inside.
void add_buildings(Scene& scene) {
  constexpr double kStepDepth_m = 3.5, kStepRise_m = 2.5, kStandFront_m = 13.0, kStandBaseHeight_m = 4.0;
  constexpr double kStandHalfLength_m = 100.0;
  constexpr int kSteps = 5;
  constexpr float kStandReflectivity = 0.5F, kPitReflectivity = 0.6F, kGarageReflectivity = 0.8F;
  for (const double x_center : {-380.0, -120.0, 180.0}) {
    for (int k = 0; k < kSteps; ++k) {
      const double h = kStandBaseHeight_m + kStepRise_m * k;
      const double y = -(kStandFront_m + kStepDepth_m * (k + 0.5));
      scene.add(Box{Eigen::Vector3d(x_center, y, 0.5 * h),
                    Eigen::Vector3d(kStandHalfLength_m, 0.5 * kStepDepth_m, 0.5 * h), 0.0, kStandReflectivity});
    }
  }
  // Pit building x in [-270, 170], y in [16, 32]; garage walls stick out of its front to y = 12.
  constexpr double kPitCenterX_m = -50.0, kPitCenterY_m = 24.0, kPitHalfLength_m = 220.0, kPitHalfDepth_m = 8.0;
  constexpr double kPitHeight_m = 8.0;
  scene.add(Box{Eigen::Vector3d(kPitCenterX_m, kPitCenterY_m, 0.5 * kPitHeight_m),
                Eigen::Vector3d(kPitHalfLength_m, kPitHalfDepth_m, 0.5 * kPitHeight_m), 0.0, kPitReflectivity});
  constexpr int kGarages = 12;
  constexpr double kGarageFirstX_m = -250.0, kGaragePitch_m = 40.0, kGarageWallY_m = 14.0;
  constexpr double kGarageWallHalfThickness_m = 0.3, kGarageWallHalfDepth_m = 2.0, kGarageWallHeight_m = 3.0;
  for (int k = 0; k < kGarages; ++k)
    scene.add(Box{Eigen::Vector3d(kGarageFirstX_m + kGaragePitch_m * k, kGarageWallY_m, 0.5 * kGarageWallHeight_m),
                  Eigen::Vector3d(kGarageWallHalfThickness_m, kGarageWallHalfDepth_m, 0.5 * kGarageWallHeight_m), 0.0,
                  kGarageReflectivity});
}
}  // namespace

World build_racetrack_world() {
  const std::vector<Eigen::Vector2d> vertices = {{-600, 0},  {600, 0},   {800, 250},  {800, 740},  {500, 770},
                                                 {420, 560}, {200, 620}, {-300, 620}, {-700, 400}, {-780, 150}};
  // Radii in travel order: corners at vertices 1, 2, ..., 9, 0.
  const std::vector<double> radii = {120, 250, 60, 45, 45, 80, 150, 90, 70, 100};
  Path path = Path::from_polyline(vertices, radii, true);
  SpeedPlan plan(path, {kMaxSpeed_m_s, kMaxLateralAccel_m_s2, kMaxLongitudinalAccel_m_s2, kInitialRest_s, true}, {});

  World w;
  Rng rng(kLayoutSeed);
  add_wall_along(w.scene, path, kBarrierOffset_m, kBarrierStep_m, kBarrierHeight_m, kBarrierThickness_m,
                 kBarrierReflectivity, 0.0, rng);
  add_wall_along(w.scene, path, -kBarrierOffset_m, kBarrierStep_m, kBarrierHeight_m, kBarrierThickness_m,
                 kBarrierReflectivity, 0.0, rng);
  add_wall_along(w.scene, path, kFenceOffset_m, kFenceStep_m, kFenceHeight_m, kFenceThickness_m, kFenceReflectivity,
                 kFenceGapChance, rng);
  add_wall_along(w.scene, path, -kFenceOffset_m, kFenceStep_m, kFenceHeight_m, kFenceThickness_m, kFenceReflectivity,
                 kFenceGapChance, rng);
  add_trackside_objects(w.scene, path, rng);
  add_buildings(w.scene);
  w.scene.build_index(kGridCell_m);

  w.facts["lap_length_m"] = std::to_string(path.length_m());
  w.facts["lap_time_s"] = std::to_string(plan.lap_time_s());             // a steady (flying) lap
  w.facts["first_lap_time_s"] = std::to_string(plan.plan_duration_s());  // rest + standing start + lap
  w.facts["initial_rest_s"] = std::to_string(kInitialRest_s);
  w.facts["lidar"] = "3 raster LiDARs (front, left, right), 120 deg x 128 channels x 570 columns each";
  w.motion =
      std::make_shared<VehicleMotion>(std::move(path), std::move(plan), SmoothCurve({0.0}, {0.0}), kBodyHeight_m);
  w.T_imu_lidar = mount_pose({0.6, 0.0, 0.5}, 0.01, 0.02, -0.005);
  const auto elevations = uniform_elevations_rad(kChannels, kLowestElevation_rad, kHighestElevation_rad);
  const double yaw_side = kFov_rad;  // the side sensors continue where the front one ends
  w.lidars.push_back(raster_lidar(0, mount_pose({0.4, 0.0, 0.0}, 0.0, 0.0, 0.0), elevations, kColumns, kFov_rad,
                                  kMinRange_m, kMaxRange_m));
  w.lidars.push_back(raster_lidar(1, mount_pose({0.0, 0.3, 0.0}, yaw_side, 0.0, 0.0), elevations, kColumns, kFov_rad,
                                  kMinRange_m, kMaxRange_m));
  w.lidars.push_back(raster_lidar(2, mount_pose({0.0, -0.3, 0.0}, -yaw_side, 0.0, 0.0), elevations, kColumns, kFov_rad,
                                  kMinRange_m, kMaxRange_m));
  return w;
}

}  // namespace farlio::sim
