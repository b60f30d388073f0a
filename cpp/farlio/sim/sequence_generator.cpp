#include "farlio/sim/sequence_generator.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "farlio/core/time.hpp"
#include "farlio/sim/imu_errors.hpp"
#include "farlio/sim/imu_model.hpp"
#include "farlio/sim/random.hpp"

namespace farlio::sim {
namespace {
constexpr float kIntensityScale = 100.0F;
/// Columns per TBB task.
constexpr std::size_t kColumnsPerTask = 16;
/// Sampling rate of the trajectory statistics in description().
constexpr double kStatsRate_hz = 50.0;

/// The profile's world with the configured LiDAR model in place of the profile's sensors.
World world_for(const SimConfig& config) {
  World w = build_world(config.profile);
  if (config.lidar_model == LidarModel::Profile) return w;
  const SE3 mount = w.lidars.front().T_lidar_sensor;
  w.lidars = {lidar_model(config.lidar_model, 0, mount, config.lidar_rate_hz)};
  w.facts["lidar"] = lidar_model_name(config.lidar_model);
  return w;
}

struct Firing {  // one firing of one sensor
  double time_fraction;
  std::uint8_t sensor;
  int column;
  std::size_t first_ray;  // index of its first ray in the scan's ray order
};

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string vec(const Eigen::Vector3d& v) { return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]"; }

/// The error model's fields and the turn-on biases drawn for this seed (only when the model is on,
/// so that meta.yaml of the default IMU is unchanged).
void add_imu_errors(const ImuErrorConfig& e, std::uint64_t seed, std::map<std::string, std::string>& d) {
  const ImuErrorDraw draw = draw_imu_errors(e, seed);
  d["gyro_turn_on_bias_rad_s"] = vec(draw.gyro_turn_on_bias_rad_s);
  d["accel_turn_on_bias_m_s2"] = vec(draw.accel_turn_on_bias_m_s2);
  d["gyro_turn_on_bias_std_rad_s"] = num(e.gyro_turn_on_bias_std_rad_s);
  d["accel_turn_on_bias_std_m_s2"] = num(e.accel_turn_on_bias_std_m_s2);
  d["gyro_scale_factor_std_ppm"] = num(e.gyro_scale_factor_std_ppm);
  d["accel_scale_factor_std_ppm"] = num(e.accel_scale_factor_std_ppm);
  d["gyro_misalignment_std_mrad"] = num(e.gyro_misalignment_std_mrad);
  d["accel_misalignment_std_mrad"] = num(e.accel_misalignment_std_mrad);
  d["gyro_g_sensitivity_std_rad_s_per_m_s2"] = num(e.gyro_g_sensitivity_std_rad_s_per_m_s2);
  const VibrationConfig& v = e.vibration;
  d["vibration_wheel_radius_m"] = num(v.wheel_radius_m);
  d["vibration_accel_wheel_amplitude_m_s2_per_m_s"] = vec(v.accel_wheel_amplitude_m_s2_per_m_s);
  d["vibration_gyro_wheel_amplitude_rad_s_per_m_s"] = vec(v.gyro_wheel_amplitude_rad_s_per_m_s);
  d["vibration_accel_noise_std_m_s2_per_m_s"] = vec(v.accel_noise_std_m_s2_per_m_s);
  d["vibration_gyro_noise_std_rad_s_per_m_s"] = vec(v.gyro_noise_std_rad_s_per_m_s);
}
/// A motion that begins offset_s into another.
class LaterStart final : public MotionModel {
 public:
  LaterStart(std::shared_ptr<const MotionModel> motion, double offset_s)
      : motion_(std::move(motion)), offset_s_(offset_s) {}
  [[nodiscard]] BodyState state(double t_s) const override { return motion_->state(t_s + offset_s_); }

 private:
  std::shared_ptr<const MotionModel> motion_;
  double offset_s_;
};
}  // namespace

SequenceGenerator::SequenceGenerator(const SimConfig& config) : config_(config) {
  if (!(config_.lidar_rate_hz > 0.0) || !(config_.imu_rate_hz > 0.0) || !(config_.duration_s > 0.0))
    throw std::invalid_argument("SimConfig: lidar_rate_hz, imu_rate_hz and duration_s must be positive");
  world_ = std::make_shared<const World>(world_for(config_));
  if (!(config_.motion_start_s >= 0.0) || !std::isfinite(config_.motion_start_s))
    throw std::invalid_argument("SimConfig: motion_start_s must be finite and not negative");
  motion_ = config_.motion_start_s > 0.0 ? std::make_shared<const LaterStart>(world_->motion, config_.motion_start_s)
                                         : world_->motion;
  if (!(config_.imu_time_offset_s >= 0.0) || !(config_.imu_time_offset_s * config_.imu_rate_hz < 1.0))
    throw std::invalid_argument("SimConfig: imu_time_offset_s must be in [0, 1 / imu_rate_hz)");
  validate_imu_errors(config_.imu_errors);
  period_ns_ = std::llround(kNsPerS / config_.lidar_rate_hz);
}

std::size_t SequenceGenerator::num_scans() const {
  return static_cast<std::size_t>(std::floor(config_.duration_s * kNsPerS / static_cast<double>(period_ns_)));
}

std::int64_t SequenceGenerator::scan_start_ns(std::size_t i) const {
  return config_.start_stamp_ns + static_cast<std::int64_t>(i) * period_ns_;
}

double SequenceGenerator::seconds_since_start(std::int64_t stamp_ns) const {
  return ns_to_seconds(stamp_ns - config_.start_stamp_ns);
}

BodyState SequenceGenerator::state(std::int64_t stamp_ns) const {
  return motion_->state(seconds_since_start(stamp_ns));
}

Scan SequenceGenerator::scan(std::size_t i) const {
  const auto& lidars = world_->lidars;
  // Firings in time order (ties: by sensor), with the offset of their rays.
  std::vector<Firing> firings;
  for (const auto& l : lidars)
    for (int c = 0; c < l.num_columns; ++c) firings.push_back({l.column_time_fraction(c), l.id, c, 0});
  std::stable_sort(firings.begin(), firings.end(), [](const Firing& a, const Firing& b) {
    return a.time_fraction < b.time_fraction || (a.time_fraction == b.time_fraction && a.sensor < b.sensor);
  });
  std::size_t num_rays = 0;
  for (auto& f : firings) {
    f.first_ray = num_rays;
    num_rays += lidars[f.sensor].num_channels();
  }

  Scan out;
  out.start_stamp_ns = scan_start_ns(i);
  out.end_stamp_ns = out.start_stamp_ns + period_ns_;
  const double start_s = seconds_since_start(out.start_stamp_ns);
  const double period_s = ns_to_seconds(period_ns_);
  const NoiseConfig& noise = config_.noise;

  // One slot per ray, compacted afterwards so the order is independent of threading.
  std::vector<Vec3f> points(num_rays);
  std::vector<float> times(num_rays), intensity(num_rays);
  std::vector<std::uint8_t> sensor(num_rays), valid(num_rays, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, firings.size(), kColumnsPerTask), [&](const auto& range) {
    for (std::size_t f = range.begin(); f != range.end(); ++f) {
      const Firing& firing = firings[f];
      const LidarSensor& l = lidars[firing.sensor];
      const double t_rel_s = firing.time_fraction * period_s;
      const SE3 T_world_lidar = motion_->state(start_s + t_rel_s).pose_world_body * world_->T_imu_lidar;
      const SE3 T_world_sensor = T_world_lidar * l.T_lidar_sensor;
      const Eigen::Vector3d origin = T_world_sensor.translation();
      const Mat3d R_world_sensor = T_world_sensor.rotation();
      for (std::size_t ch = 0; ch < l.num_channels(); ++ch) {
        const std::size_t ray = firing.first_ray + ch;
        if (!config_.noise_free && uniform01(config_.seed, Stream::LidarDropout, i, ray) < noise.dropout_probability)
          continue;
        const Eigen::Vector3d dir_sensor = l.direction(firing.column, ch, i);
        const Eigen::Vector3d dir_world = R_world_sensor * dir_sensor;
        const auto hit = world_->scene.cast(origin, dir_world, l.max_range_m);
        if (!hit) continue;
        double range_m = hit->range_m;
        if (!config_.noise_free)
          range_m += noise.range_noise_std_m * standard_normal(config_.seed, Stream::LidarRange, i, ray);
        if (range_m < l.min_range_m || range_m > l.max_range_m) continue;
        points[ray] = (l.T_lidar_sensor * (range_m * dir_sensor)).cast<float>();
        times[ray] = static_cast<float>(t_rel_s);
        intensity[ray] = kIntensityScale * hit->reflectivity * static_cast<float>(std::abs(hit->normal.dot(dir_world)));
        sensor[ray] = l.id;
        valid[ray] = 1;
      }
    }
  });
  const auto count = static_cast<std::size_t>(std::count(valid.begin(), valid.end(), std::uint8_t{1}));
  out.points.reserve(count);
  out.time_s.reserve(count);
  out.intensity.reserve(count);
  out.sensor_id.reserve(count);
  for (std::size_t r = 0; r < num_rays; ++r) {
    if (!valid[r]) continue;
    out.points.push_back(points[r]);
    out.time_s.push_back(times[r]);
    out.intensity.push_back(intensity[r]);
    out.sensor_id.push_back(sensor[r]);
  }
  return out;
}

Scan SequenceGenerator::motion_compensated(const Scan& scan) const {
  const auto T_world_lidar = [&](std::int64_t stamp_ns) {
    return state(stamp_ns).pose_world_body * world_->T_imu_lidar;
  };
  const SE3 T_end_world = T_world_lidar(scan.end_stamp_ns).inverse();
  Scan out;
  out.start_stamp_ns = out.end_stamp_ns = scan.end_stamp_ns;
  out.intensity = scan.intensity;
  out.sensor_id = scan.sensor_id;
  out.points.reserve(scan.size());
  // the points of one firing share their time: one pose per run of equal times
  SE3 T_end_point;
  double pose_time_s = -1.0;  // the point time T_end_point is for (none yet)
  for (std::size_t k = 0; k < scan.size(); ++k) {
    const double t_s = scan.has_time() ? scan.time_s[k] : scan.duration_s();
    if (t_s != pose_time_s) {
      T_end_point = T_end_world * T_world_lidar(scan.start_stamp_ns + seconds_to_ns(t_s));
      pose_time_s = t_s;
    }
    out.points.push_back((T_end_point * scan.points[k].cast<double>()).cast<float>());
  }
  return out;
}

std::vector<ImuSample> SequenceGenerator::imu() const { return generate_imu(*motion_, config_); }

Trajectory SequenceGenerator::groundtruth_body(double rate_hz) const {
  if (!(rate_hz > 0.0)) throw std::invalid_argument("groundtruth_body: rate_hz must be positive");
  Trajectory traj;
  const auto count = static_cast<std::size_t>(std::floor(config_.duration_s * rate_hz)) + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const std::int64_t stamp = config_.start_stamp_ns + std::llround(static_cast<double>(k) / rate_hz * kNsPerS);
    traj.push_back(stamp, state(stamp).pose_world_body);
  }
  return traj;
}

Trajectory SequenceGenerator::groundtruth_scans() const {
  Trajectory traj;
  for (std::size_t i = 0; i < num_scans(); ++i) {
    const std::int64_t stamp = scan_start_ns(i) + period_ns_;
    traj.push_back(stamp, state(stamp).pose_world_body);
  }
  return traj;
}

std::map<std::string, std::string> SequenceGenerator::description() const {
  std::map<std::string, std::string> d = world_->facts;
  d["profile"] = profile_name(config_.profile);
  d["seed"] = std::to_string(config_.seed);
  d["start_stamp_ns"] = std::to_string(config_.start_stamp_ns);  // t = 0 of the times in seconds
  d["duration_s"] = num(config_.duration_s);
  d["motion_start_s"] = num(config_.motion_start_s);  // t = 0 is this instant of the profile's motion
  d["noise_free"] = config_.noise_free ? "true" : "false";
  d["lidar_model"] = lidar_model_name(config_.lidar_model);
  d["lidar_rate_hz"] = num(config_.lidar_rate_hz);
  d["imu_rate_hz"] = num(config_.imu_rate_hz);
  d["imu_time_offset_s"] = num(config_.imu_time_offset_s);
  d["gravity_m_s2"] = num(config_.gravity_m_s2);
  d["num_scans"] = std::to_string(num_scans());
  d["num_primitives"] = std::to_string(world_->scene.num_primitives());
  d["range_noise_std_m"] = num(config_.noise.range_noise_std_m);
  d["dropout_probability"] = num(config_.noise.dropout_probability);
  d["gyro_noise_std_rad_s"] = num(config_.noise.gyro_noise_std_rad_s);
  d["accel_noise_std_m_s2"] = num(config_.noise.accel_noise_std_m_s2);
  d["gyro_bias_walk_rad_s2_sqrt_hz"] = num(config_.noise.gyro_bias_walk_rad_s2_sqrt_hz);
  d["accel_bias_walk_m_s3_sqrt_hz"] = num(config_.noise.accel_bias_walk_m_s3_sqrt_hz);
  if (config_.imu_errors.any()) add_imu_errors(config_.imu_errors, config_.seed, d);
  // Trajectory statistics over the duration.
  double max_speed = 0.0, sum_speed = 0.0, max_lateral = 0.0, max_rate = 0.0, path_m = 0.0;
  double z_min = std::numeric_limits<double>::infinity(), z_max = -z_min;
  Eigen::Vector3d prev = motion_->state(0.0).pose_world_body.translation();
  const auto count = static_cast<std::size_t>(std::floor(config_.duration_s * kStatsRate_hz)) + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const BodyState s = motion_->state(static_cast<double>(k) / kStatsRate_hz);
    const double v = s.velocity_world_m_s.norm();
    max_speed = std::max(max_speed, v);
    sum_speed += v;
    if (v > 0.0) max_lateral = std::max(max_lateral, s.acceleration_world_m_s2.cross(s.velocity_world_m_s).norm() / v);
    max_rate = std::max(max_rate, s.angular_velocity_body_rad_s.norm());
    const Eigen::Vector3d p = s.pose_world_body.translation();
    path_m += (p - prev).norm();
    prev = p;
    z_min = std::min(z_min, p.z());
    z_max = std::max(z_max, p.z());
  }
  d["max_speed_m_s"] = num(max_speed);
  d["mean_speed_m_s"] = num(sum_speed / static_cast<double>(count));
  d["max_lateral_accel_m_s2"] = num(max_lateral);
  d["max_angular_rate_rad_s"] = num(max_rate);
  d["path_length_m"] = num(path_m);
  d["height_range_m"] = num(z_max - z_min);
  return d;
}

}  // namespace farlio::sim
