// The urban profile: a grid of city blocks on hilly ground (the height varies along x), with
// buildings, parked cars, poles and trees; a car drives a route of straights and right-angle
// turns with full stops, closing a block at its end; one 64-beam spinning LiDAR (mount_car_lidar,
// shared with the tunnel).
#include <cmath>
#include <numbers>

#include "farlio/sim/random.hpp"
#include "farlio/sim/world.hpp"

namespace farlio::sim {
namespace {
constexpr std::uint64_t kLayoutSeed = 0x757262616E303031ULL;
constexpr double kDeg = std::numbers::pi / 180.0;

constexpr double kBlockPitch_m = 90.0;        // street centre line to street centre line
constexpr double kBuildingSetback_m = 12.0;   // street centre line to the building line
constexpr int kBlockMin = -3, kBlockMax = 6;  // block index range in x and y
constexpr int kLotsPerSide = 3;
constexpr double kBuildingChance = 0.85, kBuildingHeightMin_m = 8.0, kBuildingHeightMax_m = 35.0;
constexpr double kLotMargin_m = 1.0, kFoundationDepth_m = 2.0;
constexpr double kCarOffset_m = 7.5, kCarSlot_m = 7.0, kCarChance = 0.5, kCarClearance_m = 20.0;
constexpr double kCarHalfLength_m = 2.25, kCarHalfWidth_m = 0.95, kCarHalfHeight_m = 0.75;
constexpr double kCarSink_m = 0.2;
constexpr double kPoleOffset_m = 10.5, kPoleSpacing_m = 30.0, kPoleRadius_m = 0.12, kPoleHeight_m = 7.0;
constexpr double kTreeOffset_m = 11.0, kTreeSpacing_m = 40.0, kTreeChance = 0.6;
constexpr double kTrunkRadius_m = 0.2, kTrunkHeight_m = 3.0, kCrownRadius_m = 1.8, kCrownTop_m = 7.0;

// Terrain along x: smooth hills (the road grade peaks near 8 %).
const SmoothCurve& terrain() {
  static const SmoothCurve curve({-200.0, 60.0, 200.0, 300.0, 420.0, 560.0}, {0.0, 0.0, 6.0, 6.0, 1.0, 1.0});
  return curve;
}
constexpr int kGroundPiecesPerRamp = 32;

// Driving.
constexpr double kMaxSpeed_m_s = 14.0, kMaxLateralAccel_m_s2 = 4.5, kMaxLongitudinalAccel_m_s2 = 2.5;
constexpr double kInitialRest_s = 2.0, kStopHold_s = 4.0, kTurnRadius_m = 16.0, kBodyHeight_m = 0.6;
// Sensor: 64 beams from -24.9 to +2 degrees, 1875 azimuth steps.
constexpr std::size_t kChannels = 64;
constexpr double kLowestElevation_rad = -24.9 * kDeg, kHighestElevation_rad = 2.0 * kDeg;
constexpr int kColumns = 1875;
constexpr double kMinRange_m = 1.0, kMaxRange_m = 120.0, kGridCell_m = 10.0;

GroundProfile tessellated_ground() {
  const SmoothCurve& h = terrain();
  std::vector<double> xs, zs;
  for (std::size_t k = 0; k + 1 < h.knots_x().size(); ++k) {
    const double x0 = h.knots_x()[k], x1 = h.knots_x()[k + 1];
    const int pieces = h.knots_y()[k] == h.knots_y()[k + 1] ? 1 : kGroundPiecesPerRamp;
    for (int i = 0; i < pieces; ++i) {
      const double x = x0 + (x1 - x0) * i / pieces;
      xs.push_back(x);
      zs.push_back(h.value(x));
    }
  }
  xs.push_back(h.last_x());
  zs.push_back(h.last_y());
  return {xs, zs, 0.25F};
}

void add_box_on_ground(Scene& scene, const GroundProfile& g, double x0, double y0, double x1, double y1,
                       double height_m, float reflectivity) {
  const double z_lo = std::min(g.height_m(x0), g.height_m(x1)) - kFoundationDepth_m;
  const double z_hi = std::max(g.height_m(x0), g.height_m(x1)) + height_m;
  add_block(scene, x0, x1, y0, y1, z_lo, z_hi, reflectivity);
}

void add_blocks(Scene& scene, const GroundProfile& g, Rng& rng) {
  const double inner_m = kBlockPitch_m - 2.0 * kBuildingSetback_m;
  const double lot_m = inner_m / kLotsPerSide;
  for (int bx = kBlockMin; bx < kBlockMax; ++bx) {
    for (int by = kBlockMin; by < kBlockMax; ++by) {
      const double x_base = bx * kBlockPitch_m + kBuildingSetback_m, y_base = by * kBlockPitch_m + kBuildingSetback_m;
      for (int i = 0; i < kLotsPerSide; ++i) {
        for (int j = 0; j < kLotsPerSide; ++j) {
          const bool interior = i > 0 && i + 1 < kLotsPerSide && j > 0 && j + 1 < kLotsPerSide;
          if (interior || !rng.chance(kBuildingChance)) continue;  // courtyards and empty lots
          const double x0 = x_base + i * lot_m + rng.uniform(0.0, kLotMargin_m);
          const double y0 = y_base + j * lot_m + rng.uniform(0.0, kLotMargin_m);
          const double x1 = x_base + (i + 1) * lot_m - rng.uniform(0.0, kLotMargin_m);
          const double y1 = y_base + (j + 1) * lot_m - rng.uniform(0.0, kLotMargin_m);
          add_box_on_ground(scene, g, x0, y0, x1, y1, rng.uniform(kBuildingHeightMin_m, kBuildingHeightMax_m),
                            static_cast<float>(rng.uniform(0.3, 0.8)));
        }
      }
    }
  }
}

/// Parked cars, poles and trees along both sides of every street segment.
void add_street_furniture(Scene& scene, const GroundProfile& g, Rng& rng) {
  for (int along_x = 0; along_x < 2; ++along_x) {
    for (int line = kBlockMin; line <= kBlockMax; ++line) {
      for (int seg = kBlockMin; seg < kBlockMax; ++seg) {
        const double c_m = line * kBlockPitch_m;  // the street's centre line coordinate
        const double a_m = seg * kBlockPitch_m;   // segment start along the street
        // (u along the street, v across) -> (x, y)
        auto xy = [&](double u, double v) {
          return along_x ? Eigen::Vector2d(u, c_m + v) : Eigen::Vector2d(c_m + v, u);
        };
        const double yaw = along_x ? 0.0 : 0.5 * std::numbers::pi;
        for (const double side : {-1.0, 1.0}) {
          for (double u = a_m + kCarClearance_m; u + kCarSlot_m < a_m + kBlockPitch_m - kCarClearance_m;
               u += kCarSlot_m) {
            if (!rng.chance(kCarChance)) continue;
            const Eigen::Vector2d p = xy(u + 0.5 * kCarSlot_m, side * kCarOffset_m);
            const double z = g.height_m(p.x()) - kCarSink_m + kCarHalfHeight_m;
            scene.add(Box{Eigen::Vector3d(p.x(), p.y(), z),
                          Eigen::Vector3d(kCarHalfLength_m, kCarHalfWidth_m, kCarHalfHeight_m),
                          yaw + rng.uniform(-0.05, 0.05), static_cast<float>(rng.uniform(0.2, 0.9))});
          }
          for (double u = a_m + kBuildingSetback_m; u < a_m + kBlockPitch_m - kBuildingSetback_m; u += kPoleSpacing_m) {
            const Eigen::Vector2d p = xy(u + rng.uniform(0.0, 0.3 * kPoleSpacing_m), side * kPoleOffset_m);
            const double z0 = g.height_m(p.x()) - kFoundationDepth_m;
            scene.add(Cylinder{p, kPoleRadius_m, z0, g.height_m(p.x()) + kPoleHeight_m, 0.8F});
          }
          for (double u = a_m + kBuildingSetback_m; u < a_m + kBlockPitch_m - kBuildingSetback_m; u += kTreeSpacing_m) {
            if (!rng.chance(kTreeChance)) continue;
            const Eigen::Vector2d p =
                xy(u + rng.uniform(0.0, kTreeSpacing_m - kBuildingSetback_m), side * kTreeOffset_m);
            const double z0 = g.height_m(p.x());
            scene.add(Cylinder{p, kTrunkRadius_m, z0 - kFoundationDepth_m, z0 + kTrunkHeight_m, 0.4F});
            scene.add(Cylinder{p, kCrownRadius_m, z0 + kTrunkHeight_m, z0 + kCrownTop_m, 0.3F});
          }
        }
      }
    }
  }
}
}  // namespace

World build_urban_world() {
  const double b = kBlockPitch_m;
  // The last two legs close a block: north onto the first street, then back along it to the start
  // (a revisit in the opposite direction, ~160 s into the drive, for loop closure).
  const std::vector<Eigen::Vector2d> route = {{0, 0},         {3 * b, 0},  {3 * b, 2 * b}, {b, 2 * b}, {b, 3 * b},
                                              {4 * b, 3 * b}, {4 * b, -b}, {2 * b, -b},    {2 * b, 0}, {0, 0}};
  Path path = Path::from_polyline(route, std::vector<double>(route.size() - 2, kTurnRadius_m), false);
  SpeedPlan plan(path, {kMaxSpeed_m_s, kMaxLateralAccel_m_s2, kMaxLongitudinalAccel_m_s2, kInitialRest_s},
                 {{1, kStopHold_s}, {3, kStopHold_s}, {5, kStopHold_s}});

  World w;
  Rng rng(kLayoutSeed);
  GroundProfile ground = tessellated_ground();
  add_blocks(w.scene, ground, rng);
  add_street_furniture(w.scene, ground, rng);
  w.scene.set_ground(ground);
  w.scene.build_index(kGridCell_m);

  w.facts["route_length_m"] = std::to_string(path.length_m());
  w.motion = std::make_shared<VehicleMotion>(std::move(path), std::move(plan), terrain(), kBodyHeight_m);
  mount_car_lidar(w);
  return w;
}

void mount_car_lidar(World& w) {
  w.facts["lidar"] = "64-beam spinning LiDAR, -24.9..+2 deg, 1875 azimuth steps";
  w.T_imu_lidar = mount_pose({0.3, 0.0, 1.2}, -0.015, 0.01, 0.008);
  w.lidars.push_back(spinning_lidar(0, SE3::identity(),
                                    uniform_elevations_rad(kChannels, kLowestElevation_rad, kHighestElevation_rad),
                                    kColumns, kMinRange_m, kMaxRange_m));
}

}  // namespace farlio::sim
