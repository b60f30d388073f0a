#include "farlio/core/config_fields.hpp"

#include <algorithm>
#include <charconv>
#include <sstream>
#include <stdexcept>

namespace farlio {

std::vector<ConfigField> config_fields(Config& c) {
  return {
      {"preprocess.min_range_m", &c.preprocess.min_range_m, "points closer to the sensor are dropped"},
      {"preprocess.max_range_m", &c.preprocess.max_range_m, "points farther from the sensor are dropped"},
      {"preprocess.undistort", &c.preprocess.undistort, "motion undistortion of points with per-point times"},
      {"map.voxel_size_m", &c.map.voxel_size_m, "edge of a voxel of the submap (paper: 4 m)"},
      {"map.auto_voxel_size", &c.map.auto_voxel_size,
       "scale the voxel to the first scan: clamp(p90 range / auto_range_ratio, auto_min_voxel_size_m, voxel_size_m)"},
      {"map.auto_range_ratio", &c.map.auto_range_ratio, "p90 range of the first scan over the voxel size (auto)"},
      {"map.auto_min_voxel_size_m", &c.map.auto_min_voxel_size_m, "smallest voxel the auto scaling picks"},
      {"map.max_points_per_voxel", &c.map.max_points_per_voxel,
       "N_max; the point spacing is voxel_size_m / sqrt(N_max) (paper: 40)"},
      {"map.point_spacing_m", &c.map.point_spacing_m, "minimum point distance in a voxel; 0: voxel_size_m / sqrt(N_max)"},
      {"map.covariance_neighbors", &c.map.covariance_neighbors, "k nearest neighbours of a covariance (paper: 10)"},
      {"map.covariance_epsilon", &c.map.covariance_epsilon, "eps of the Frobenius regularisation, eq. (1)"},
      {"map.line_eigenvalue_ratio", &c.map.line_eigenvalue_ratio,
       "a covariance is line-like when its middle eigenvalue is below ratio x the smallest (0: off)"},
      {"map.removal_radius_m", &c.map.removal_radius_m, "voxels farther than this from the pose are removed"},
      {"map.refresh_covariances", &c.map.refresh_covariances,
       "recompute covariances of existing points in voxels that receive new points"},
      {"map.initial_voxel_capacity", &c.map.initial_voxel_capacity, "voxels preallocated (grows by doubling)"},
      {"map.max_voxel_capacity", &c.map.max_voxel_capacity, "hard limit of the submap in voxels"},
      {"density.enabled", &c.density.enabled, "adaptive submap density (ASMD)"},
      {"density.close_range_m", &c.density.close_range_m, "range over which the scan's density is averaged"},
      {"density.slope_points_per_m", &c.density.slope_points_per_m, "linear decay of the per-voxel limit with range"},
      {"density.frame_map_max_points_per_voxel", &c.density.frame_map_max_points_per_voxel,
       "cap of the per-scan frame map (source covariances)"},
      {"threshold.initial_threshold_m", &c.threshold.initial_threshold_m, "sigma before any deviation is observed"},
      {"threshold.min_motion_m", &c.threshold.min_motion_m, "model deviations below this are not sampled"},
      {"threshold.max_range_m", &c.threshold.max_range_m, "range that turns a rotation into a displacement"},
      {"threshold.max_threshold_m", &c.threshold.max_threshold_m, "cap of sigma"},
      {"registration.sparsity_aware", &c.registration.sparsity_aware, "GICP (true) or point-to-point ICP (false)"},
      {"registration.point_to_point_sigma_m", &c.registration.point_to_point_sigma_m,
       "residual sigma of points without covariance (point-to-point); 0: half the map spacing; paper: 0.0316"},
      {"registration.skip_line_pairs", &c.registration.skip_line_pairs,
       "leave out correspondences whose covariances are both line-like"},
      {"registration.max_iterations", &c.registration.max_iterations, "Gauss-Newton iterations at most"},
      {"registration.convergence_norm", &c.registration.convergence_norm, "stop when |dx| falls below this"},
      {"registration.time_budget_factor", &c.registration.time_budget_factor, "time budget in LiDAR periods"},
      {"registration.damping", &c.registration.damping, "lambda added to the diagonal of H"},
      {"fusion.enabled", &c.fusion.enabled, "fuse the IMU (LIO); false or no IMU: LiDAR-only odometry"},
      {"fusion.step_s", &c.fusion.step_s, "fixed EKF step (paper: 0.01 s = 100 Hz)"},
      {"fusion.history_s", &c.fusion.history_s, "state history kept for delay compensation and pose queries"},
      {"fusion.max_extrapolation_s", &c.fusion.max_extrapolation_s, "pose_at() may predict this far beyond the newest step"},
      {"fusion.imu_gap_limit_s", &c.fusion.imu_gap_limit_s, "IMU samples farther apart are a gap: the last input is held"},
      {"fusion.gyro_input_std_rad_s", &c.fusion.gyro_input_std_rad_s, "std of the gyro input over one step (process noise B Q B^T)"},
      {"fusion.accel_input_std_m_s2", &c.fusion.accel_input_std_m_s2, "std of the accelerometer input over one step (process noise B Q B^T)"},
      {"fusion.initial_position_std_m", &c.fusion.initial_position_std_m, "initial position std at initialisation"},
      {"fusion.initial_attitude_std_rad", &c.fusion.initial_attitude_std_rad, "initial roll/pitch/yaw std at initialisation"},
      {"fusion.initial_velocity_std_m_s", &c.fusion.initial_velocity_std_m_s, "initial velocity std when the first LiDAR result has no velocity"},
      {"fusion.lidar_position_std_m", &c.fusion.lidar_position_std_m, "LiDAR position measurement std per axis"},
      {"fusion.lidar_roll_pitch_std_rad", &c.fusion.lidar_roll_pitch_std_rad, "LiDAR roll and pitch measurement std"},
      {"fusion.lidar_yaw_std_rad", &c.fusion.lidar_yaw_std_rad, "LiDAR yaw measurement std"},
      {"fusion.lidar_velocity_std_m_s", &c.fusion.lidar_velocity_std_m_s, "LiDAR body velocity (eq. 6) measurement std per axis"},
      {"fusion.outlier_rejection", &c.fusion.outlier_rejection, "Mahalanobis outlier rejection per measurement group"},
      {"fusion.outlier_chi2_3dof", &c.fusion.outlier_chi2_3dof, "chi-square gate for 3-dof groups (99.9 %: 16.27)"},
      {"fusion.outlier_chi2_2dof", &c.fusion.outlier_chi2_2dof, "chi-square gate for 2-dof groups (99.9 %: 13.82)"},
      {"fusion.max_consecutive_rejections", &c.fusion.max_consecutive_rejections, "consecutive rejected LiDAR positions before re-initialising from LiDAR"},
      {"fusion.reference_angles", &c.fusion.reference_angles, "fuse roll/pitch reference angles (ablation switch)"},
      {"fusion.reference_roll_std_rad", &c.fusion.reference_roll_std_rad, "reference roll angle measurement std"},
      {"fusion.reference_pitch_std_rad", &c.fusion.reference_pitch_std_rad, "reference pitch angle measurement std"},
      {"fusion.reference_filter_taps", &c.fusion.reference_filter_taps, "taps of the Hann low-pass of the reference angle terms (odd)"},
      {"fusion.reference_max_sin", &c.fusion.reference_max_sin, "clamp of the asin argument; clamped reference angles are not fused"},
      {"fusion.delay_compensation", &c.fusion.delay_compensation, "shift delayed measurements by eq. 10 (ablation switch)"},
      {"fusion.update_spread_steps", &c.fusion.update_spread_steps, "N: a LiDAR result is fused over N steps with N*R each (0: LiDAR period / step)"},
      {"fusion.max_update_spread_steps", &c.fusion.max_update_spread_steps, "cap of the automatic N"},
      {"fusion.standstill_bias", &c.fusion.standstill_bias, "learn the gyro bias at standstill (ablation switch)"},
      {"fusion.standstill_max_speed_m_s", &c.fusion.standstill_max_speed_m_s, "standstill: estimated speed below this"},
      {"fusion.standstill_max_gyro_rad_s", &c.fusion.standstill_max_gyro_rad_s, "standstill: |gyro| below this"},
      {"fusion.standstill_max_accel_deviation_m_s2", &c.fusion.standstill_max_accel_deviation_m_s2, "standstill: | |accel| - g | below this"},
      {"fusion.bias_window_samples", &c.fusion.bias_window_samples, "gyro bias running-mean window in samples"},
      {"fusion.bias_prior_samples", &c.fusion.bias_prior_samples, "weight of the initial gyro bias in the running mean, in samples"},
      {"fusion.gyro_bias_init_x_rad_s", &c.fusion.gyro_bias_init_x_rad_s, "initial gyro bias x"},
      {"fusion.gyro_bias_init_y_rad_s", &c.fusion.gyro_bias_init_y_rad_s, "initial gyro bias y"},
      {"fusion.gyro_bias_init_z_rad_s", &c.fusion.gyro_bias_init_z_rad_s, "initial gyro bias z"},
      {"fusion.accel_bias_x_m_s2", &c.fusion.accel_bias_x_m_s2, "accelerometer bias x (not estimated, as in the paper)"},
      {"fusion.accel_bias_y_m_s2", &c.fusion.accel_bias_y_m_s2, "accelerometer bias y (not estimated, as in the paper)"},
      {"fusion.accel_bias_z_m_s2", &c.fusion.accel_bias_z_m_s2, "accelerometer bias z (not estimated, as in the paper)"},
      {"fusion.accel_unit_detection", &c.fusion.accel_unit_detection, "detect an accelerometer reporting in g and scale it"},
      {"fusion.accel_unit_detection_samples", &c.fusion.accel_unit_detection_samples, "first samples whose mean |accel| decides the unit"},
      {"cuda.max_scan_points", &c.cuda.max_scan_points, "device buffers: points of one scan (all LiDARs merged)"},
      {"cuda.max_map_voxels", &c.cuda.max_map_voxels, "device buffers: submap voxels (N_max points each)"},
      {"cuda.max_frame_voxels", &c.cuda.max_frame_voxels, "device buffers: voxels of the per-scan frame map"},
      {"device", &c.device, "scan pipeline backend: auto (CUDA when a GPU is present, else CPU), cpu or cuda"},
      {"num_threads", &c.num_threads, "CPU threads of this pipeline (0: all)"},
  };
}

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

ConfigField find_field(Config& c, const std::string& name) {
  auto fields = config_fields(c);
  for (auto& f : fields) {
    if (f.name == name) return f;
  }
  std::sort(fields.begin(), fields.end(), [&](const ConfigField& a, const ConfigField& b) {
    return edit_distance(a.name, name) < edit_distance(b.name, name);
  });
  constexpr std::size_t kSuggestions = 3;
  std::string msg = "unknown config field '" + name + "'; closest:";
  for (std::size_t i = 0; i < std::min(kSuggestions, fields.size()); ++i) msg += " " + fields[i].name;
  throw std::invalid_argument(msg);
}

template <typename T>
T parse_number(const std::string& name, const std::string& text) {
  T v{};
  const auto* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end) {
    throw std::invalid_argument("config field '" + name + "': cannot read '" + text + "' as a number");
  }
  return v;
}

}  // namespace

void set_config_field(Config& config, const std::string& name, const std::string& value) {
  const ConfigField f = find_field(config, name);
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, Device>) {
          *p = parse_device(value, name);
        } else if constexpr (std::is_same_v<T, bool>) {
          if (value == "true" || value == "True" || value == "1") *p = true;
          else if (value == "false" || value == "False" || value == "0") *p = false;
          else throw std::invalid_argument("config field '" + name + "': expected true or false, got '" + value + "'");
        } else {
          *p = parse_number<T>(name, value);
        }
      },
      f.value);
}

std::string get_config_field(const Config& config, const std::string& name) {
  Config copy = config;
  const ConfigField f = find_field(copy, name);
  std::ostringstream os;
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, Device>) {
          os << device_name(*p);
        } else if constexpr (std::is_same_v<T, bool>) {
          os << (*p ? "true" : "false");
        } else {
          char buf[64];  // shortest text that reads back to the same value
          const auto r = std::to_chars(buf, buf + sizeof(buf), *p);
          os << std::string_view(buf, static_cast<std::size_t>(r.ptr - buf));
        }
      },
      f.value);
  return os.str();
}

}  // namespace farlio
