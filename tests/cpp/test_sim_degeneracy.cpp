// The tunnel profile is degenerate for LiDAR registration from its geometry alone: in the bare
// middle of the tunnel the point-to-plane information of a scan, sum(n n^T) over the exact
// surface normals of every ray's hit, has no component along the track (x), while near the
// portals it constrains all three directions.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;
using namespace farlio::sim;

namespace {
/// A scan whose weakest direction carries less than this share of the strongest is degenerate.
constexpr double kDegenerateRatio = 1e-3;
/// Near the portals the weakest direction must carry at least this share.
constexpr double kConstrainedRatio = 1e-2;
/// The weakest direction of a degenerate scan is the track direction within this (|cos|).
constexpr double kMinAlongTrackCosine = 0.999;
constexpr int kBisectionSteps = 60;

/// Translational point-to-plane information of one full sweep of the LiDAR from the pose at
/// time t_s (exact hits, no noise; the pose is held for the sweep, only the geometry matters).
Eigen::Matrix3d information_at(const SequenceGenerator& gen, double t_s) {
  const SE3 T_world_lidar =
      gen.state(gen.config().start_stamp_ns + std::llround(t_s * 1e9)).pose_world_body * gen.T_imu_lidar();
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (const LidarSensor& l : gen.lidars()) {
    const SE3 T_world_sensor = T_world_lidar * l.T_lidar_sensor;
    for (int c = 0; c < l.num_columns; ++c) {
      for (std::size_t ch = 0; ch < l.elevations_rad.size(); ++ch) {
        const Eigen::Vector3d dir = T_world_sensor.rotation() * l.direction(c, ch);
        const auto hit = gen.scene().cast(T_world_sensor.translation(), dir, l.max_range_m);
        if (hit && hit->range_m >= l.min_range_m) info += hit->normal * hit->normal.transpose();
      }
    }
  }
  return info;
}

struct Weakest {
  double ratio;               ///< smallest / largest eigenvalue
  double second_ratio;        ///< second smallest / largest
  Eigen::Vector3d direction;  ///< eigenvector of the smallest
};

Weakest weakest_direction(const Eigen::Matrix3d& info) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(info);  // ascending eigenvalues
  const Eigen::Vector3d ev = es.eigenvalues();
  return {ev[0] / ev[2], ev[1] / ev[2], es.eigenvectors().col(0)};
}

double fact(const SequenceGenerator& gen, const std::string& key) { return std::stod(gen.description().at(key)); }

/// The time at which the body passes x (s(t) is monotonic; bisection over the duration).
double time_at_x(const SequenceGenerator& gen, double x_m) {
  double lo = 0.0, hi = gen.config().duration_s;
  for (int i = 0; i < kBisectionSteps; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double x = gen.state(gen.config().start_stamp_ns + std::llround(mid * 1e9)).pose_world_body.translation().x();
    (x < x_m ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
}  // namespace

TEST(SimDegeneracy, BareTunnelIsDegenerateAlongTheTrackOnly) {
  const SequenceGenerator gen(default_config(Profile::Tunnel));
  const double x0 = fact(gen, "featureless_start_x_m"), x1 = fact(gen, "featureless_end_x_m");
  const double range_m = gen.lidars().front().max_range_m;
  // Mid-section, and just out of the LiDAR's reach of the last features at either end.
  for (const double x : {0.5 * (x0 + x1), x0 + range_m + 1.0, x1 - range_m - 1.0}) {
    const Weakest w = weakest_direction(information_at(gen, time_at_x(gen, x)));
    EXPECT_LT(w.ratio, kDegenerateRatio) << "x = " << x;
    EXPECT_GT(std::abs(w.direction.x()), kMinAlongTrackCosine) << "x = " << x << ": " << w.direction.transpose();
    EXPECT_GT(w.second_ratio, kConstrainedRatio) << "x = " << x << ": only one direction is degenerate";
  }
}

TEST(SimDegeneracy, PortalsAndTheirSurroundingsAreConstrained) {
  const SequenceGenerator gen(default_config(Profile::Tunnel));
  const double tunnel0 = fact(gen, "tunnel_start_x_m"), tunnel1 = fact(gen, "tunnel_end_x_m");
  const double x0 = fact(gen, "featureless_start_x_m"), x1 = fact(gen, "featureless_end_x_m");
  // Before the entrance portal, inside the structured zone behind it, in the structured zone
  // before the exit, and out in the open after the exit.
  for (const double x : {0.5 * tunnel0, 0.5 * (tunnel0 + x0), 0.5 * (x1 + tunnel1), tunnel1 + 0.5 * tunnel0}) {
    const Weakest w = weakest_direction(information_at(gen, time_at_x(gen, x)));
    EXPECT_GT(w.ratio, kConstrainedRatio) << "x = " << x << ": weakest " << w.direction.transpose();
  }
}
