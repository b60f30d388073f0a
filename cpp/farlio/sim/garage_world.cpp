// The garage profile: a car drives up through a closed four-level parking garage whose levels
// are identical (the same pillars, parked cars, walls and ramps every 3.2 m of height), then
// laps the top level once more. Every level above the first stands over a level that looks the
// same from the inside, 3.2 m below: a place recognised by its looks alone is the wrong level,
// which is what a loop closure must refuse. One 64-beam spinning LiDAR (as urban).
//
// Plan (metres): the interior is x in [0, 72], y in [0, 41]. Aisles run along y = 8 (bottom),
// y = 28 (top), x = 8 (left) and x = 64 (right); the ramp lane y in [34, 40] rises from x = 56
// (this level) to x = 16 (the level above), beside a low wall that separates it from the top
// aisle. Parked cars line the bottom and side walls and two rows between the bottom and top aisles.
#include <cmath>
#include <numbers>
#include <string>

#include "farlio/sim/random.hpp"
#include "farlio/sim/world.hpp"

namespace farlio::sim {
namespace {
constexpr std::uint64_t kLayoutSeed = 0x6761726167653031ULL;

// Building.
constexpr int kLevels = 4;  // levels 0..3 and the roof slab above level 3
constexpr double kLevelHeight_m = 3.2, kSlabThickness_m = 0.3, kWallThickness_m = 0.3;
constexpr double kLength_m = 72.0, kWidth_m = 41.0;
constexpr float kSlabReflectivity = 0.35F, kWallReflectivity = 0.5F, kGroundReflectivity = 0.3F;
// Aisles (centre lines) and the ramp lane.
constexpr double kBottomAisle_y_m = 8.0, kTopAisle_y_m = 28.0, kLeftAisle_x_m = 8.0, kRightAisle_x_m = 64.0;
constexpr double kRampLane_y_m = 37.0, kRampHalfWidth_m = 3.0;
constexpr double kRampLow_x_m = 56.0, kRampHigh_x_m = 16.0, kRampPiece_m = 2.0;
constexpr double kSeparator_y0_m = 32.0, kSeparator_y1_m = 33.0, kSeparatorHeight_m = 1.0;
// Pillars (square, through every level) and parked cars (bays 2.5 m wide, 75 % taken).
constexpr double kPillarHalf_m = 0.3, kPillarPitch_m = 8.0, kPillarFirst_x_m = 16.0, kPillarLast_x_m = 56.0;
constexpr double kPillarRows_y_m[] = {18.0, 32.5};
constexpr double kBayPitch_m = 2.5, kCarChance = 0.75, kBayCentreFromWall_m = 2.6;
constexpr double kBottomBays_x_m[] = {13.0, 59.0}, kMiddleBays_x_m[] = {15.0, 57.0}, kSideBays_y_m[] = {14.0, 24.0};
constexpr double kMiddleRows_y_m[] = {13.5, 22.5};
constexpr double kCarHalfLength_m = 2.3, kCarHalfWidth_m = 0.9, kCarHalfHeight_m = 0.75;
constexpr float kPillarReflectivity = 0.55F;
// Driving: a parking-garage pace, 2 s at rest, corners of 5 m radius.
constexpr double kMaxSpeed_m_s = 6.0, kMaxLateralAccel_m_s2 = 2.0, kMaxLongitudinalAccel_m_s2 = 1.5;
constexpr double kInitialRest_s = 2.0, kBodyHeight_m = 0.6, kCornerRadius_m = 5.0;
constexpr double kStart_x_m = 14.0, kEnd_x_m = 30.0;
constexpr double kArcLengthStep_m = 0.05;
constexpr double kGridCell_m = 8.0;

double level_z(int level) { return kLevelHeight_m * level; }

/// The slab whose top is level `level`'s floor; below the roof it has the ramp lane's opening.
void add_slab(Scene& scene, int level) {
  const double z1 = level_z(level), z0 = z1 - kSlabThickness_m;
  if (level == kLevels) {
    add_block(scene, 0.0, kLength_m, 0.0, kWidth_m, z0, z1, kSlabReflectivity);
    return;
  }
  const double y0 = kRampLane_y_m - kRampHalfWidth_m, y1 = kRampLane_y_m + kRampHalfWidth_m;
  add_block(scene, 0.0, kLength_m, 0.0, y0, z0, z1, kSlabReflectivity);
  add_block(scene, 0.0, kRampHigh_x_m, y0, kWidth_m, z0, z1, kSlabReflectivity);
  add_block(scene, kRampLow_x_m, kLength_m, y0, kWidth_m, z0, z1, kSlabReflectivity);
  add_block(scene, kRampHigh_x_m, kRampLow_x_m, y1, kWidth_m, z0, z1, kSlabReflectivity);
}

/// One level's furniture on the floor at z: the low wall beside the ramp lane and the parked
/// cars, drawn from the same layout stream on every level (identical levels).
void add_level(Scene& scene, double z) {
  add_block(scene, kRampHigh_x_m, kRampLow_x_m, kSeparator_y0_m, kSeparator_y1_m, z, z + kSeparatorHeight_m,
            kWallReflectivity);
  Rng rng(kLayoutSeed);
  const auto car = [&](double x, double y, bool along_x) {
    if (!rng.chance(kCarChance)) return;
    const Eigen::Vector3d half = along_x ? Eigen::Vector3d(kCarHalfLength_m, kCarHalfWidth_m, kCarHalfHeight_m)
                                         : Eigen::Vector3d(kCarHalfWidth_m, kCarHalfLength_m, kCarHalfHeight_m);
    scene.add(Box{Eigen::Vector3d(x, y, z + kCarHalfHeight_m), half, 0.0, static_cast<float>(rng.uniform(0.2, 0.9))});
  };
  for (double x = kBottomBays_x_m[0]; x <= kBottomBays_x_m[1]; x += kBayPitch_m)  // along the bottom wall
    car(x, kBayCentreFromWall_m, false);
  for (const double y : kMiddleRows_y_m)
    for (double x = kMiddleBays_x_m[0]; x <= kMiddleBays_x_m[1]; x += kBayPitch_m) car(x, y, false);
  for (double y = kSideBays_y_m[0]; y <= kSideBays_y_m[1]; y += kBayPitch_m) {  // along the side walls
    car(kBayCentreFromWall_m, y, true);
    car(kLength_m - kBayCentreFromWall_m, y, true);
  }
}

/// The ramp from level `level` to the next: pieces of kRampPiece_m whose inclined tops follow the
/// road height (road(s) on the lane, where s = s_low + kRampLow_x_m - x) to within a centimetre.
void add_ramp(Scene& scene, const SmoothCurve& road, double s_low_m) {
  for (double xa = kRampLow_x_m; xa > kRampHigh_x_m + 1e-9; xa -= kRampPiece_m) {
    const double xb = xa - kRampPiece_m;
    const double ha = road.value(s_low_m + kRampLow_x_m - xa), hb = road.value(s_low_m + kRampLow_x_m - xb);
    Box piece{Eigen::Vector3d(0.5 * (xa + xb), kRampLane_y_m, 0.5 * (ha + hb) - 0.5 * kSlabThickness_m),
              Eigen::Vector3d(0.5 * kRampPiece_m, kRampHalfWidth_m, 0.5 * kSlabThickness_m), 0.0, kSlabReflectivity};
    piece.slope = (hb - ha) / (xb - xa);
    scene.add(piece);
  }
}

/// The route: from the bottom aisle up every ramp (a lap per level), then one more lap of the
/// top level by the top aisle, ending on it.
Path garage_route() {
  std::vector<Eigen::Vector2d> v{{kStart_x_m, kBottomAisle_y_m}};
  const std::vector<Eigen::Vector2d> ramp_lap{{kRightAisle_x_m, kBottomAisle_y_m},
                                              {kRightAisle_x_m, kRampLane_y_m},
                                              {kLeftAisle_x_m, kRampLane_y_m},
                                              {kLeftAisle_x_m, kBottomAisle_y_m}};
  const std::vector<Eigen::Vector2d> top_lap{{kRightAisle_x_m, kBottomAisle_y_m},
                                             {kRightAisle_x_m, kTopAisle_y_m},
                                             {kLeftAisle_x_m, kTopAisle_y_m},
                                             {kLeftAisle_x_m, kBottomAisle_y_m}};
  for (int r = 0; r + 1 < kLevels; ++r) v.insert(v.end(), ramp_lap.begin(), ramp_lap.end());
  v.insert(v.end(), top_lap.begin(), top_lap.end());
  v.insert(v.end(), top_lap.begin(), top_lap.begin() + 2);
  v.emplace_back(kEnd_x_m, kTopAisle_y_m);
  return Path::from_polyline(v, std::vector<double>(v.size() - 2, kCornerRadius_m), false);
}

/// The arc lengths at which the route enters each ramp (x = kRampLow_x_m on the ramp lane,
/// heading -x), in order.
std::vector<double> ramp_entries(const Path& path) {
  std::vector<double> s_entries;
  PathPoint prev = path.at(0.0);
  for (double s = kArcLengthStep_m; s <= path.length_m(); s += kArcLengthStep_m) {
    const PathPoint p = path.at(s);
    const bool on_lane = std::abs(p.position_m.y() - kRampLane_y_m) < 0.5 * kRampHalfWidth_m;
    if (on_lane && prev.position_m.x() > kRampLow_x_m && p.position_m.x() <= kRampLow_x_m)
      s_entries.push_back(s - kArcLengthStep_m * (kRampLow_x_m - p.position_m.x()) /
                                  (prev.position_m.x() - p.position_m.x()));
    prev = p;
  }
  return s_entries;
}
}  // namespace

World build_garage_world() {
  Path path = garage_route();
  const std::vector<double> entries = ramp_entries(path);
  // Road height over arc length: level r until the ramp's low end, level r + 1 from its high end.
  SmoothCurve road({0.0}, {0.0});
  for (std::size_t r = 0; r < entries.size(); ++r) {
    road.add_knot(entries[r], level_z(static_cast<int>(r)));
    road.add_knot(entries[r] + (kRampLow_x_m - kRampHigh_x_m), level_z(static_cast<int>(r) + 1));
  }
  SpeedPlan plan(path, {kMaxSpeed_m_s, kMaxLateralAccel_m_s2, kMaxLongitudinalAccel_m_s2, kInitialRest_s}, {});

  World w;
  for (int level = 1; level <= kLevels; ++level) add_slab(w.scene, level);
  for (int level = 0; level < kLevels; ++level) add_level(w.scene, level_z(level));
  for (const double s : entries) add_ramp(w.scene, road, s);
  const double top = level_z(kLevels);
  const double t = kWallThickness_m;
  add_block(w.scene, -t, kLength_m + t, -t, 0.0, 0.0, top, kWallReflectivity);
  add_block(w.scene, -t, kLength_m + t, kWidth_m, kWidth_m + t, 0.0, top, kWallReflectivity);
  add_block(w.scene, -t, 0.0, 0.0, kWidth_m, 0.0, top, kWallReflectivity);
  add_block(w.scene, kLength_m, kLength_m + t, 0.0, kWidth_m, 0.0, top, kWallReflectivity);
  for (const double y : kPillarRows_y_m)
    for (double x = kPillarFirst_x_m; x <= kPillarLast_x_m + 1e-9; x += kPillarPitch_m)
      add_block(w.scene, x - kPillarHalf_m, x + kPillarHalf_m, y - kPillarHalf_m, y + kPillarHalf_m, 0.0, top,
                kPillarReflectivity);
  w.scene.set_ground(GroundProfile({0.0}, {0.0}, kGroundReflectivity));
  w.scene.build_index(kGridCell_m);

  w.facts["levels"] = std::to_string(kLevels);
  w.facts["level_height_m"] = std::to_string(kLevelHeight_m);
  w.facts["route_length_m"] = std::to_string(path.length_m());
  w.facts["route_duration_s"] = std::to_string(plan.plan_duration_s());
  w.facts["repeated_structure"] = "identical levels 3.2 m apart (pillars, parked cars, walls, ramps)";
  for (std::size_t r = 0; r < entries.size(); ++r)
    w.facts["ramp_" + std::to_string(r) + "_entry_arc_length_m"] = std::to_string(entries[r]);
  w.motion = std::make_shared<VehicleMotion>(std::move(path), std::move(plan), std::move(road), kBodyHeight_m,
                                             RoadHeightOf::ArcLength);
  mount_car_lidar(w);
  return w;
}

}  // namespace farlio::sim
