#pragma once
// A closed-loop simulation of SensorFusion on an analytic trajectory: IMU samples (optionally
// noisy, biased, in g, with a gap), LiDAR poses at a fixed rate (noisy, delayed, optionally one
// outlier), the filter clock at 100 Hz; records the error of every step against the truth.
#include <cmath>
#include <random>
#include <vector>

#include "farlio/fusion/sensor_fusion.hpp"
#include "fusion_test_trajectory.hpp"

namespace farlio::test {

struct SimOptions {
  double duration_s = 1.0;
  double imu_hz = 100.0;
  double clock_hz = 100.0;     ///< advance_to() calls per second
  double lidar_hz = 10.0;      ///< 0: only the initialising result at t = 0
  double lidar_delay_s = 0.0;  ///< delivery delay of every LiDAR result after the first
  double gyro_noise_std_rad_s = 0.0;
  double accel_noise_std_m_s2 = 0.0;
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
  double lidar_position_noise_m = 0.0;
  double lidar_rotation_noise_rad = 0.0;
  bool accel_in_g = false;
  double imu_gap_start_s = -1.0;  ///< no IMU samples in [start, start + length)
  double imu_gap_length_s = 0.0;
  int outlier_index = -1;  ///< this LiDAR result (1-based after the first) is moved
  Eigen::Vector3d outlier_offset_m = Eigen::Vector3d::Zero();
  double outlier_yaw_offset_rad = 0.0;
  int skip_index = -1;  ///< this LiDAR result is not delivered at all
  unsigned seed = 42;
};

struct SimStep {
  double t_s;
  Eigen::Vector3d position_error_m;
  double rotation_error_deg;
};

struct SimResult {
  std::vector<SimStep> steps;
  std::vector<fusion::LidarUpdateResult> lidar_results;
  fusion::FusionStats stats;
  bool finite = true;

  [[nodiscard]] double max_position_error_m(double from_s = 0.0) const {
    double m = 0.0;
    for (const auto& s : steps)
      if (s.t_s >= from_s) m = std::max(m, s.position_error_m.norm());
    return m;
  }
  [[nodiscard]] double max_rotation_error_deg(double from_s = 0.0) const {
    double m = 0.0;
    for (const auto& s : steps)
      if (s.t_s >= from_s) m = std::max(m, s.rotation_error_deg);
    return m;
  }
  [[nodiscard]] double rms_position_error_m(double from_s = 0.0) const {
    double sum = 0.0;
    int n = 0;
    for (const auto& s : steps)
      if (s.t_s >= from_s) {
        sum += s.position_error_m.squaredNorm();
        ++n;
      }
    return n > 0 ? std::sqrt(sum / n) : 0.0;
  }
  /// The largest change of the position error from one step to the next (a jump of the output).
  [[nodiscard]] double max_error_jump_m(double from_s = 0.0) const {
    double m = 0.0;
    for (std::size_t i = 1; i < steps.size(); ++i) {
      if (steps[i].t_s >= from_s) m = std::max(m, (steps[i].position_error_m - steps[i - 1].position_error_m).norm());
    }
    return m;
  }
};

/// Runs the fusion from the true state at t = 0 (SensorFusion::initialize_known) to duration_s.
inline SimResult simulate(const TestTrajectory& traj, const FusionConfig& config, const SimOptions& o,
                          fusion::SensorFusion* fusion_out = nullptr) {
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto noise3 = [&](double std) { return Eigen::Vector3d(std * normal(rng), std * normal(rng), std * normal(rng)); };

  fusion::SensorFusion local(config, kGravity_m_s2);
  fusion::SensorFusion& f = fusion_out ? *fusion_out : local;
  SimResult r;
  const double imu_dt = 1.0 / o.imu_hz, clock_dt = 1.0 / o.clock_hz;
  int imu_k = 0;
  int lidar_k = 0;  // next LiDAR result index (0 = the initialisation with the true state)
  const int clock_steps = static_cast<int>(std::llround(o.duration_s * o.clock_hz));
  for (int c = 0; c <= clock_steps; ++c) {
    const double now = c * clock_dt;
    for (; imu_k * imu_dt <= now + 1e-12; ++imu_k) {
      const double t = imu_k * imu_dt;
      if (t >= o.imu_gap_start_s && t < o.imu_gap_start_s + o.imu_gap_length_s) continue;
      ImuSample m = traj.imu(t);
      m.gyro_rad_s += o.gyro_bias_rad_s + noise3(o.gyro_noise_std_rad_s);
      m.accel_m_s2 += noise3(o.accel_noise_std_m_s2);
      if (o.accel_in_g) m.accel_m_s2 /= kGravity_m_s2;
      f.add_imu(m);
    }
    f.advance_to(seconds_to_ns(now));
    while (true) {
      const double stamp = o.lidar_hz > 0.0 ? lidar_k / o.lidar_hz : 0.0;
      const double delivered = stamp + (lidar_k == 0 ? 0.0 : o.lidar_delay_s);
      if ((lidar_k > 0 && o.lidar_hz <= 0.0) || delivered > now + 1e-12) break;
      if (lidar_k == 0) {
        f.initialize_known(seconds_to_ns(0.0), traj.pose(0.0), traj.velocity_body(0.0));
      } else {
        const SE3 truth = traj.pose(stamp);
        Eigen::Vector3d p = truth.translation() + noise3(o.lidar_position_noise_m);
        if (lidar_k == o.outlier_index) p += o.outlier_offset_m;
        Eigen::Matrix3d R = truth.rotation() * so3_exp(noise3(o.lidar_rotation_noise_rad));
        if (lidar_k == o.outlier_index) R = so3_exp(Eigen::Vector3d(0.0, 0.0, o.outlier_yaw_offset_rad)) * R;
        // A skipped result still draws its noise, so that the other results stay identical.
        if (lidar_k != o.skip_index) {
          r.lidar_results.push_back(f.add_lidar(seconds_to_ns(stamp), SE3(R, p), Eigen::Vector3d::Zero(), false));
        } else {
          r.lidar_results.emplace_back();
        }
      }
      ++lidar_k;
    }
    const fusion::BodyEstimate e = f.estimate();
    if (!e.valid) continue;
    const double t_est = ns_to_seconds(e.stamp_ns);
    const SE3 truth = traj.pose(t_est);
    if (!e.pose.translation().allFinite()) r.finite = false;
    r.steps.push_back({t_est, e.pose.translation() - truth.translation(), rotation_error_deg(e.pose, truth)});
  }
  r.stats = f.stats();
  return r;
}

/// A configuration without the optional parts (pure prediction + LiDAR updates).
inline FusionConfig plain_config() {
  FusionConfig c;
  c.reference_angles.enabled = false;
  c.standstill.gyro_bias = false;
  return c;
}

}  // namespace farlio::test
