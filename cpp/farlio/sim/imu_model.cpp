#include "farlio/sim/imu_model.hpp"

#include <cmath>
#include <optional>

#include "farlio/core/time.hpp"
#include "farlio/sim/imu_errors.hpp"
#include "farlio/sim/random.hpp"
#include "farlio/sim/vibration.hpp"

namespace farlio::sim {

ImuSample ideal_imu_reading(const BodyState& s, double gravity_m_s2) {
  const Eigen::Vector3d g_world(0.0, 0.0, -gravity_m_s2);
  ImuSample out;
  out.gyro_rad_s = s.angular_velocity_body_rad_s;
  out.accel_m_s2 = s.pose_world_body.rotation().transpose() * (s.acceleration_world_m_s2 - g_world);
  return out;
}

std::vector<ImuSample> generate_imu(const MotionModel& motion, const SimConfig& config) {
  const auto count =
      static_cast<std::size_t>(std::floor((config.duration_s - config.imu_time_offset_s) * config.imu_rate_hz)) + 1;
  const double dt_s = 1.0 / config.imu_rate_hz;
  const NoiseConfig& n = config.noise;
  Eigen::Vector3d gyro_bias = n.gyro_bias_initial_rad_s, accel_bias = n.accel_bias_initial_m_s2;
  // The error model only when it has something to add, so that without it the readings are
  // bit-identical to those of NoiseConfig alone.
  std::optional<ImuErrorDraw> errors;
  std::optional<Vibration> vibration;
  if (!config.noise_free && config.imu_errors.any()) {
    errors = draw_imu_errors(config.imu_errors, config.seed);
    gyro_bias += errors->gyro_turn_on_bias_rad_s;
    accel_bias += errors->accel_turn_on_bias_m_s2;
    if (config.imu_errors.vibration.any())
      vibration.emplace(config.imu_errors.vibration, config.seed, config.imu_rate_hz);
  }
  std::vector<ImuSample> out;
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double t_s = static_cast<double>(k) * dt_s + config.imu_time_offset_s;
    const BodyState state = motion.state(t_s);
    ImuSample s = ideal_imu_reading(state, config.gravity_m_s2);
    s.stamp_ns = config.start_stamp_ns + seconds_to_ns(t_s);
    if (!config.noise_free) {
      if (errors) s = apply_imu_errors(*errors, s);
      if (vibration) {
        const Vibration::Reading v = vibration->next(k, state.velocity_world_m_s.norm());
        s.gyro_rad_s += v.gyro_rad_s;
        s.accel_m_s2 += v.accel_m_s2;
      }
      s.gyro_rad_s += gyro_bias + n.gyro_noise_std_rad_s * standard_normal3(config.seed, Stream::ImuGyro, k);
      s.accel_m_s2 += accel_bias + n.accel_noise_std_m_s2 * standard_normal3(config.seed, Stream::ImuAccel, k);
      const double sqrt_dt = std::sqrt(dt_s);
      gyro_bias += n.gyro_bias_walk_rad_s2_sqrt_hz * sqrt_dt * standard_normal3(config.seed, Stream::ImuGyroBias, k);
      accel_bias += n.accel_bias_walk_m_s3_sqrt_hz * sqrt_dt * standard_normal3(config.seed, Stream::ImuAccelBias, k);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace farlio::sim
