#pragma once
// Body motion models with analytic derivatives: the exact truth that the IMU model samples
// and that the LiDAR model uses for the pose at every firing instant.
#include <Eigen/Core>

#include "farlio/core/se3.hpp"
#include "farlio/sim/path.hpp"
#include "farlio/sim/smooth_curve.hpp"
#include "farlio/sim/speed_plan.hpp"

namespace farlio::sim {

/// The exact state of the body (IMU) frame at one instant.
struct BodyState {
  SE3 pose_world_body;
  Eigen::Vector3d velocity_world_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration_world_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_body_rad_s = Eigen::Vector3d::Zero();
};

/// Z-Y-X Euler angles (yaw about world z, then pitch, then roll) and their rates.
struct EulerZyx {
  double yaw_rad = 0.0, pitch_rad = 0.0, roll_rad = 0.0;
  double yaw_rate_rad_s = 0.0, pitch_rate_rad_s = 0.0, roll_rate_rad_s = 0.0;
};
/// R = Rz(yaw) * Ry(pitch) * Rx(roll).
Mat3d euler_zyx_rotation(const EulerZyx& e);
/// Angular velocity in the rotated (body) frame of the Euler angle rates.
Eigen::Vector3d euler_zyx_body_rate(const EulerZyx& e);

class MotionModel {
 public:
  virtual ~MotionModel() = default;
  /// State at t_s seconds after the sequence start.
  [[nodiscard]] virtual BodyState state(double t_s) const = 0;
};

/// What a VehicleMotion's road height is a function of: the world x (a landscape's ground,
/// GroundProfile) or the arc length along the path (a road that crosses itself at different
/// heights: a parking garage's ramps).
enum class RoadHeightOf { WorldX, ArcLength };

/// A ground vehicle following a path: body x along the path tangent, pitched with the road
/// grade, no roll; the body sits body_height_m above the road surface z = road(x) or road(s).
class VehicleMotion final : public MotionModel {
 public:
  VehicleMotion(Path path, SpeedPlan plan, SmoothCurve road_height_m, double body_height_m,
                RoadHeightOf height_of = RoadHeightOf::WorldX);
  [[nodiscard]] BodyState state(double t_s) const override;
  [[nodiscard]] const Path& path() const { return path_; }
  [[nodiscard]] const SpeedPlan& plan() const { return plan_; }

 private:
  Path path_;
  SpeedPlan plan_;
  SmoothCurve road_;
  double body_height_m_;
  RoadHeightOf height_of_;
};

/// How a hand-held sensor bobs and sways while walking (all tied to the distance walked, so
/// it stops when the walker stands still).
struct WalkStyle {
  double eye_height_m = 0.0;
  double stride_m = 0.0;  ///< one vertical bob per stride
  double bob_amplitude_m = 0.0;
  double pitch_sway_rad = 0.0;  ///< nodding, once per stride
  double roll_sway_rad = 0.0;   ///< side to side, once per two strides
};

/// A person walking a path while turning the sensor: yaw = path heading + yaw_offset(t).
class WalkerMotion final : public MotionModel {
 public:
  WalkerMotion(Path path, SpeedPlan plan, SmoothCurve yaw_offset_of_t_rad, WalkStyle style);
  [[nodiscard]] BodyState state(double t_s) const override;
  [[nodiscard]] const SpeedPlan& plan() const { return plan_; }

 private:
  Path path_;
  SpeedPlan plan_;
  SmoothCurve yaw_offset_;
  WalkStyle style_;
};

}  // namespace farlio::sim
