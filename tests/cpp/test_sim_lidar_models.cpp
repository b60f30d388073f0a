// LiDAR models of real sensors on the profiles' vehicles: each model's field of view and point
// rate, the Livox patterns' non-repetition (scan after scan fills the field of view), points in
// firing-time order, exact points on the scene, and the names.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;
using namespace farlio::sim;

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kAngleSlack_rad = 0.01 * kDeg;
constexpr double kSurfaceTolerance_m = 2e-3;

SimConfig with_model(Profile p, LidarModel m, bool noise_free = true) {
  SimConfig c = default_config(p);
  c.duration_s = 12.0;
  c.noise_free = noise_free;
  c.lidar_model = m;
  return c;
}

/// (azimuth, elevation) of a sensor-frame direction.
std::pair<double, double> az_el(const Eigen::Vector3d& d) {
  return {std::atan2(d.y(), d.x()), std::asin(std::clamp(d.z() / d.norm(), -1.0, 1.0))};
}

/// Cells of (azimuth, elevation), cell_deg wide, that the sensor's directions hit over scans [0, scans).
std::set<std::pair<int, int>> cells_hit(const LidarSensor& l, std::size_t scans, double cell_deg = 1.0) {
  std::set<std::pair<int, int>> cells;
  for (std::size_t s = 0; s < scans; ++s)
    for (int c = 0; c < l.num_columns; ++c)
      for (std::size_t ch = 0; ch < l.num_channels(); ++ch) {
        const auto [az, el] = az_el(l.direction(c, ch, s));
        const double cell_rad = cell_deg * kDeg;
        cells.insert({static_cast<int>(std::floor(az / cell_rad)), static_cast<int>(std::floor(el / cell_rad))});
      }
  return cells;
}
}  // namespace

struct FieldOfView {
  LidarModel model;
  double points_per_second;
  double max_abs_azimuth_deg;  // 180: all around
  double lowest_elevation_deg, highest_elevation_deg;
};

class LidarModels : public ::testing::TestWithParam<FieldOfView> {};

TEST_P(LidarModels, PointRateAndFieldOfViewAreTheModels) {
  const FieldOfView& f = GetParam();
  for (const double rate_hz : {10.0, 20.0}) {
    const LidarSensor l = lidar_model(f.model, 0, SE3::identity(), rate_hz);
    EXPECT_NEAR(static_cast<double>(l.num_rays()) * rate_hz, f.points_per_second, 0.01 * f.points_per_second);
    double lowest = 1e9, highest = -1e9, widest = 0.0;
    for (std::size_t s = 0; s < 3; ++s)
      for (int c = 0; c < l.num_columns; ++c)
        for (std::size_t ch = 0; ch < l.num_channels(); ++ch) {
          const Eigen::Vector3d d = l.direction(c, ch, s);
          ASSERT_NEAR(d.norm(), 1.0, 1e-12);
          const auto [az, el] = az_el(d);
          lowest = std::min(lowest, el);
          highest = std::max(highest, el);
          widest = std::max(widest, std::abs(az));
        }
    // within the field of view, and reaching its edges (to 1.5°)
    EXPECT_GE(lowest, f.lowest_elevation_deg * kDeg - kAngleSlack_rad);
    EXPECT_LE(highest, f.highest_elevation_deg * kDeg + kAngleSlack_rad);
    EXPECT_LT(lowest, (f.lowest_elevation_deg + 1.5) * kDeg);
    EXPECT_GT(highest, (f.highest_elevation_deg - 1.5) * kDeg);
    EXPECT_LE(widest, f.max_abs_azimuth_deg * kDeg + kAngleSlack_rad);
    EXPECT_GT(widest, (f.max_abs_azimuth_deg - 1.5) * kDeg);
  }
}

// The Avia's six lasers are 0.6° apart in elevation around a rosette of radius 38.6°: its
// elevations reach 38.6 + 1.5 degrees, its azimuths 38.6 * 70.4 / 77.2 + a little (elevation
// offsets tilt the rose's edge only in elevation).
INSTANTIATE_TEST_SUITE_P(Models, LidarModels,
                         ::testing::Values(FieldOfView{LidarModel::Avia, 240'000.0, 35.2, -40.1, 40.1},
                                           FieldOfView{LidarModel::Mid360, 200'000.0, 180.0, -7.0, 52.0},
                                           FieldOfView{LidarModel::Vlp16, 18'000.0 * 16, 180.0, -15.0, 15.0},
                                           FieldOfView{LidarModel::Hdl32, 22'500.0 * 32, 180.0, -30.67, 10.67},
                                           FieldOfView{LidarModel::Os128, 10'240.0 * 128, 180.0, -22.5, 22.5}));

TEST(LidarModels, LivoxPatternsDoNotRepeatAndFillTheirFieldOfView) {
  for (const LidarModel m : {LidarModel::Avia, LidarModel::Mid360}) {
    const LidarSensor l = lidar_model(m, 0, SE3::identity(), 10.0);
    // the same firing of consecutive scans points elsewhere
    EXPECT_GT(std::acos(std::clamp(l.direction(7, 0, 0).dot(l.direction(7, 0, 1)), -1.0, 1.0)), 0.1 * kDeg);
    // ten scans hit 0.25° cells that one does not
    constexpr double kFineCell_deg = 0.25;
    const std::size_t one_scan = cells_hit(l, 1, kFineCell_deg).size();
    const std::size_t one_second = cells_hit(l, 10, kFineCell_deg).size();
    EXPECT_GT(static_cast<double>(one_second), 3.0 * static_cast<double>(one_scan))
        << lidar_model_name(m) << ": " << one_scan << " -> " << one_second;
  }
  // in 1 s the Mid-360 hits nearly every 1° cell of its 360° x 59°
  const LidarSensor mid360 = lidar_model(LidarModel::Mid360, 0, SE3::identity(), 10.0);
  EXPECT_GT(static_cast<double>(cells_hit(mid360, 10).size()), 0.98 * 360 * 59);
  // in 1 s the rosette hits nearly every 1° cell inside its rim (the rose is densest at its rim)
  const LidarSensor avia = lidar_model(LidarModel::Avia, 0, SE3::identity(), 10.0);
  const auto hit = cells_hit(avia, 10);
  std::size_t inside = 0, covered = 0;
  for (int az = -30; az < 30; ++az)
    for (int el = -30; el < 30; ++el) {
      if (std::hypot((az + 0.5) / (35.2 / 38.6), el + 0.5) > 30.0) continue;
      ++inside;
      covered += hit.count({az, el});
    }
  EXPECT_GT(static_cast<double>(covered), 0.9 * static_cast<double>(inside)) << covered << " of " << inside;
  // a grid sensor repeats itself
  const LidarSensor vlp = lidar_model(LidarModel::Vlp16, 0, SE3::identity(), 10.0);
  EXPECT_EQ(vlp.direction(7, 3, 0), vlp.direction(7, 3, 5));
  EXPECT_EQ(cells_hit(vlp, 1), cells_hit(vlp, 3));
}

TEST(LidarModels, OnAProfileTheModelReplacesItsSensorsAndItsPointsLieOnTheScene) {
  for (const LidarModel m : {LidarModel::Avia, LidarModel::Mid360, LidarModel::Vlp16}) {
    const SequenceGenerator gen(with_model(Profile::Urban, m));
    ASSERT_EQ(gen.lidars().size(), 1U);
    EXPECT_EQ(gen.description().at("lidar_model"), lidar_model_name(m));
    const Scan scan = gen.scan(100);  // moving
    ASSERT_GT(scan.size(), 1000U) << lidar_model_name(m);
    std::size_t checked = 0;
    for (std::size_t k = 0; k < scan.size(); ++k) {
      if (k > 0) ASSERT_GE(scan.time_s[k], scan.time_s[k - 1]);  // in firing-time order
      if (k % 37 != 0) continue;
      // the point seen from the sensor at its firing time lies on the scene along its ray
      const std::int64_t stamp = scan.start_stamp_ns + std::llround(static_cast<double>(scan.time_s[k]) * 1e9);
      const SE3 T_world_sensor = gen.state(stamp).pose_world_body * gen.T_imu_lidar() * gen.lidars()[0].T_lidar_sensor;
      const Eigen::Vector3d q = gen.state(stamp).pose_world_body * gen.T_imu_lidar() * scan.points[k].cast<double>();
      const Eigen::Vector3d origin = T_world_sensor.translation();
      const double range = (q - origin).norm();
      const auto surface = gen.scene().cast(origin, (q - origin) / range, gen.lidars()[0].max_range_m);
      ASSERT_TRUE(surface.has_value());
      EXPECT_NEAR(surface->range_m, range, kSurfaceTolerance_m);
      ++checked;
    }
    EXPECT_GT(checked, 20U);
  }
  // the profile's own sensors by default (the racetrack's three)
  EXPECT_EQ(SequenceGenerator(with_model(Profile::Racetrack, LidarModel::Profile)).lidars().size(), 3U);
}

TEST(LidarModels, NamesRoundTripAndABadNameListsTheValidOnes) {
  for (const LidarModel m : {LidarModel::Profile, LidarModel::Avia, LidarModel::Mid360, LidarModel::Vlp16,
                             LidarModel::Hdl32, LidarModel::Os128})
    EXPECT_EQ(parse_lidar_model(lidar_model_name(m)), m);
  try {
    (void)parse_lidar_model("velodyne");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("avia, mid360"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)lidar_model(LidarModel::Profile, 0, SE3::identity(), 10.0), std::invalid_argument);
}
