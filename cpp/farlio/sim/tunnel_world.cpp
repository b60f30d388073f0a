// The tunnel profile: a car accelerates from standstill to 100 km/h on a 1.1 km straight road
// along x and drives through an 850 m tunnel (x in [50, 900] m): flat floor, two straight
// parallel walls and a ceiling. Emergency niches and wall lamps exist only near the portals; the
// 600 m in between are bare, so a scan there constrains every direction except the one along the
// track (a degenerate case for LiDAR registration). Outside the tunnel, buildings, poles and
// trees line the road. One 64-beam spinning LiDAR (as urban).
#include <cmath>
#include <string>

#include "farlio/sim/random.hpp"
#include "farlio/sim/world.hpp"

namespace farlio::sim {
namespace {
constexpr std::uint64_t kLayoutSeed = 0x74756E6E656C3031ULL;

// Road and driving: straight along +x from the origin, 0 -> 100 km/h in 15 s, then cruising.
constexpr double kRouteLength_m = 1100.0;
constexpr double kMaxSpeed_m_s = 100.0 / 3.6, kMaxLateralAccel_m_s2 = 4.0, kMaxLongitudinalAccel_m_s2 = 3.5;
constexpr double kInitialRest_s = 2.0, kBodyHeight_m = 0.6;
// The tunnel: inner cross-section 11 m x 6 m; the bare middle between the two structured zones.
constexpr double kTunnelStart_x_m = 50.0, kTunnelEnd_x_m = 900.0;
constexpr double kFeaturelessStart_x_m = 200.0, kFeaturelessEnd_x_m = 800.0;
constexpr double kTunnelHalfWidth_m = 5.5, kCeilingHeight_m = 6.0, kShellThickness_m = 1.0;
constexpr float kWallReflectivity = 0.45F, kCeilingReflectivity = 0.35F;
// Portals: a facade around each tunnel mouth.
constexpr double kPortalDepth_m = 10.0, kPortalHalfWidth_m = 40.0, kPortalHeight_m = 15.0;
constexpr float kPortalReflectivity = 0.5F;
// Emergency niches (recesses in the walls) and wall lamps in the structured zones.
constexpr double kNicheSpacingMin_m = 15.0, kNicheSpacingMax_m = 30.0;
constexpr double kNicheLength_m = 3.0, kNicheDepth_m = 1.5, kNicheHeight_m = 3.5;
constexpr double kLampSpacing_m = 10.0, kLampLength_m = 1.2, kLampDepth_m = 0.3, kLampHeight_m = 0.3;
constexpr double kLampBottom_m = 4.0;
constexpr float kNicheReflectivity = 0.6F, kLampReflectivity = 0.9F;
// Outside: roadside buildings, poles and trees along the open road.
constexpr double kOutsideStart_x_m = -100.0;
constexpr double kBuildingSetbackMin_m = 14.0, kBuildingSetbackMax_m = 18.0;
constexpr double kBuildingLengthMin_m = 12.0, kBuildingLengthMax_m = 30.0, kBuildingGapMax_m = 8.0;
constexpr double kBuildingDepthMin_m = 8.0, kBuildingDepthMax_m = 20.0;
constexpr double kBuildingHeightMin_m = 6.0, kBuildingHeightMax_m = 25.0, kBuildingChance = 0.8;
constexpr double kPoleOffset_m = 8.5, kPoleSpacing_m = 25.0, kPoleJitter_m = 5.0, kPoleRadius_m = 0.12,
                 kPoleHeight_m = 7.0;
constexpr double kTreeOffset_m = 11.0, kTreeSpacing_m = 20.0, kTreeChance = 0.5;
constexpr double kTrunkRadius_m = 0.2, kTrunkHeight_m = 3.0, kCrownRadius_m = 1.8, kCrownTop_m = 7.0;
constexpr float kPoleReflectivity = 0.8F, kTrunkReflectivity = 0.4F, kCrownReflectivity = 0.3F;
constexpr float kGroundReflectivity = 0.25F;
constexpr double kGridCell_m = 10.0;
constexpr int kBisectionSteps = 60;

/// Niche start positions along one wall: random spacing within [begin, end - length].
std::vector<double> niche_starts(double begin_m, double end_m, Rng& rng) {
  std::vector<double> xs;
  for (double x = begin_m + rng.uniform(0.0, kNicheSpacingMin_m); x + kNicheLength_m <= end_m;
       x += rng.uniform(kNicheSpacingMin_m, kNicheSpacingMax_m))
    xs.push_back(x);
  return xs;
}

/// One tunnel wall (side +1: y > 0) from portal to portal, interrupted by niches: each niche
/// is a recess with a back wall and a lintel up to the ceiling.
void add_wall(Scene& scene, double side, const std::vector<double>& niches) {
  const double y_in = side * kTunnelHalfWidth_m, y_out = side * (kTunnelHalfWidth_m + kShellThickness_m);
  const double y_back = side * (kTunnelHalfWidth_m + kNicheDepth_m);
  double x = kTunnelStart_x_m;
  for (const double n0 : niches) {
    const double n1 = n0 + kNicheLength_m;
    add_block(scene, x, n0, y_in, y_out, 0.0, kCeilingHeight_m, kWallReflectivity);
    add_block(scene, n0, n1, y_back, y_back + side * kShellThickness_m, 0.0, kCeilingHeight_m, kNicheReflectivity);
    add_block(scene, n0, n1, y_in, y_back, kNicheHeight_m, kCeilingHeight_m, kWallReflectivity);
    x = n1;
  }
  add_block(scene, x, kTunnelEnd_x_m, y_in, y_out, 0.0, kCeilingHeight_m, kWallReflectivity);
}

void add_lamps(Scene& scene, double begin_m, double end_m) {
  for (const double side : {-1.0, 1.0}) {
    const double y_in = side * kTunnelHalfWidth_m;
    for (double x = begin_m + 0.5 * kLampSpacing_m; x + kLampLength_m <= end_m; x += kLampSpacing_m)
      add_block(scene, x, x + kLampLength_m, y_in, y_in - side * kLampDepth_m, kLampBottom_m,
                kLampBottom_m + kLampHeight_m, kLampReflectivity);
  }
}

/// The tunnel shell (walls with niches near the portals, ceiling), lamps near the portals and
/// the two portal facades.
void add_tunnel(Scene& scene, Rng& rng) {
  for (const double side : {-1.0, 1.0}) {
    std::vector<double> niches = niche_starts(kTunnelStart_x_m, kFeaturelessStart_x_m, rng);
    const std::vector<double> exit = niche_starts(kFeaturelessEnd_x_m, kTunnelEnd_x_m, rng);
    niches.insert(niches.end(), exit.begin(), exit.end());
    add_wall(scene, side, niches);
  }
  add_block(scene, kTunnelStart_x_m, kTunnelEnd_x_m, -kTunnelHalfWidth_m - kShellThickness_m,
            kTunnelHalfWidth_m + kShellThickness_m, kCeilingHeight_m, kCeilingHeight_m + kShellThickness_m,
            kCeilingReflectivity);
  add_lamps(scene, kTunnelStart_x_m, kFeaturelessStart_x_m);
  add_lamps(scene, kFeaturelessEnd_x_m, kTunnelEnd_x_m);
  for (const auto& [x0, x1] : {std::pair{kTunnelStart_x_m - kPortalDepth_m, kTunnelStart_x_m},
                               std::pair{kTunnelEnd_x_m, kTunnelEnd_x_m + kPortalDepth_m}}) {
    for (const double side : {-1.0, 1.0})
      add_block(scene, x0, x1, side * kTunnelHalfWidth_m, side * kPortalHalfWidth_m, 0.0, kPortalHeight_m,
                kPortalReflectivity);
    add_block(scene, x0, x1, -kTunnelHalfWidth_m, kTunnelHalfWidth_m, kCeilingHeight_m, kPortalHeight_m,
              kPortalReflectivity);
  }
}

/// Buildings, poles and trees on both sides of the open road over [x_begin, x_end].
void add_roadside(Scene& scene, double x_begin, double x_end, Rng& rng) {
  for (const double side : {-1.0, 1.0}) {
    for (double x = x_begin; x < x_end;) {
      const double length = std::min(rng.uniform(kBuildingLengthMin_m, kBuildingLengthMax_m), x_end - x);
      const double setback = rng.uniform(kBuildingSetbackMin_m, kBuildingSetbackMax_m);
      const double depth = rng.uniform(kBuildingDepthMin_m, kBuildingDepthMax_m);
      if (rng.chance(kBuildingChance))
        add_block(scene, x, x + length, side * setback, side * (setback + depth), 0.0,
                  rng.uniform(kBuildingHeightMin_m, kBuildingHeightMax_m), static_cast<float>(rng.uniform(0.3, 0.8)));
      x += length + rng.uniform(0.0, kBuildingGapMax_m);
    }
    for (double x = x_begin + rng.uniform(0.0, kPoleJitter_m); x < x_end;
         x += kPoleSpacing_m + rng.uniform(-kPoleJitter_m, kPoleJitter_m))
      scene.add(Cylinder{{x, side * kPoleOffset_m}, kPoleRadius_m, 0.0, kPoleHeight_m, kPoleReflectivity});
    for (double x = x_begin; x < x_end; x += kTreeSpacing_m) {
      if (!rng.chance(kTreeChance)) continue;
      const Eigen::Vector2d c(x + rng.uniform(0.0, kTreeSpacing_m), side * kTreeOffset_m);
      scene.add(Cylinder{c, kTrunkRadius_m, 0.0, kTrunkHeight_m, kTrunkReflectivity});
      scene.add(Cylinder{c, kCrownRadius_m, kTrunkHeight_m, kCrownTop_m, kCrownReflectivity});
    }
  }
}

/// The time at which the plan reaches arc length s_m (bisection; s(t) is non-decreasing).
double time_at_arc_length(const SpeedPlan& plan, double s_m) {
  double lo = 0.0, hi = plan.plan_duration_s();
  for (int i = 0; i < kBisectionSteps; ++i) {
    const double mid = 0.5 * (lo + hi);
    (plan.at(mid).s_m < s_m ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
}  // namespace

World build_tunnel_world() {
  Path path = Path::from_polyline({{0.0, 0.0}, {kRouteLength_m, 0.0}}, {}, false);
  SpeedPlan plan(path, {kMaxSpeed_m_s, kMaxLateralAccel_m_s2, kMaxLongitudinalAccel_m_s2, kInitialRest_s}, {});

  World w;
  Rng rng(kLayoutSeed);
  add_tunnel(w.scene, rng);
  add_roadside(w.scene, kOutsideStart_x_m, kTunnelStart_x_m - kPortalDepth_m, rng);
  add_roadside(w.scene, kTunnelEnd_x_m + kPortalDepth_m, kRouteLength_m, rng);
  w.scene.set_ground(GroundProfile({0.0}, {0.0}, kGroundReflectivity));
  w.scene.build_index(kGridCell_m);

  // The route starts at x = 0 along +x, so arc length and x coincide.
  w.facts["route_length_m"] = std::to_string(path.length_m());
  w.facts["tunnel_start_x_m"] = std::to_string(kTunnelStart_x_m);
  w.facts["tunnel_end_x_m"] = std::to_string(kTunnelEnd_x_m);
  w.facts["featureless_start_x_m"] = std::to_string(kFeaturelessStart_x_m);
  w.facts["featureless_end_x_m"] = std::to_string(kFeaturelessEnd_x_m);
  w.facts["featureless_start_s"] = std::to_string(time_at_arc_length(plan, kFeaturelessStart_x_m));
  w.facts["featureless_end_s"] = std::to_string(time_at_arc_length(plan, kFeaturelessEnd_x_m));
  w.facts["degenerate_direction"] = "x (along the track)";
  w.motion =
      std::make_shared<VehicleMotion>(std::move(path), std::move(plan), SmoothCurve({0.0}, {0.0}), kBodyHeight_m);
  mount_car_lidar(w);
  return w;
}

}  // namespace farlio::sim
