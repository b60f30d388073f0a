#pragma once
// A profile's world: the scene, the body motion, the LiDAR sensors and the extrinsic. The
// layout is fixed per profile (it does not depend on the seed, which only drives the noise),
// so every seed of a profile measures the same benchmark geometry.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/sim/config.hpp"
#include "farlio/sim/lidar_model.hpp"
#include "farlio/sim/motion.hpp"
#include "farlio/sim/scene.hpp"

namespace farlio::sim {

struct World {
  Scene scene;
  std::shared_ptr<const MotionModel> motion;
  std::vector<LidarSensor> lidars;
  SE3 T_imu_lidar;                           ///< maps LiDAR-frame points into the body (IMU) frame
  std::map<std::string, std::string> facts;  ///< profile-specific description entries
};

World build_world(Profile profile);
World build_racetrack_world();
World build_urban_world();
World build_handheld_world();
World build_tunnel_world();
World build_garage_world();

/// The urban car's roof LiDAR (one 64-beam spinning sensor) and its extrinsic, into w (urban,
/// tunnel and garage).
void mount_car_lidar(World& w);

/// The level, axis-aligned box [x0, x1] x [y0, y1] x [z0, z1] (corners in any order), into scene.
void add_block(Scene& scene, double x0, double x1, double y0, double y1, double z0, double z1, float reflectivity);

/// A small fixed rotation plus offset, used for the LiDAR extrinsics.
SE3 mount_pose(const Eigen::Vector3d& offset_m, double yaw_rad, double pitch_rad, double roll_rad);

}  // namespace farlio::sim
