#include "farlio/sim/world.hpp"

#include <cmath>
#include <stdexcept>

namespace farlio::sim {

World build_world(Profile profile) {
  switch (profile) {
    case Profile::Racetrack: return build_racetrack_world();
    case Profile::Urban: return build_urban_world();
    case Profile::Handheld: return build_handheld_world();
    case Profile::Tunnel: return build_tunnel_world();
    case Profile::Garage: return build_garage_world();
  }
  throw std::invalid_argument("unknown profile");
}

void add_block(Scene& scene, double x0, double x1, double y0, double y1, double z0, double z1, float reflectivity) {
  scene.add(Box{Eigen::Vector3d(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1)),
                Eigen::Vector3d(0.5 * std::abs(x1 - x0), 0.5 * std::abs(y1 - y0), 0.5 * std::abs(z1 - z0)), 0.0,
                reflectivity});
}

SE3 mount_pose(const Eigen::Vector3d& offset_m, double yaw_rad, double pitch_rad, double roll_rad) {
  EulerZyx e;
  e.yaw_rad = yaw_rad;
  e.pitch_rad = pitch_rad;
  e.roll_rad = roll_rad;
  return {euler_zyx_rotation(e), offset_m};
}

}  // namespace farlio::sim
