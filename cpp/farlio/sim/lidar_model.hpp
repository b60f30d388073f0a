#pragma once
// LiDAR sensor models. A sensor fires num_columns columns per scan period, evenly spaced in
// time from the scan start; all channels of a column fire at the same instant. Column j
// points at azimuth az_begin + (az_end - az_begin) * j / num_columns in the sensor frame
// (a spinning sensor sweeps a full turn, a raster sensor sweeps its horizontal field of view).
// Channel k points at elevations_rad[k]. Sensors are mounted in the (merged) LiDAR frame.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio::sim {

struct LidarSensor {
  std::uint8_t id = 0;
  SE3 T_lidar_sensor;  ///< the sensor's pose in the LiDAR frame named by T_imu_lidar
  std::vector<double> elevations_rad;
  int num_columns = 0;
  double azimuth_begin_rad = 0.0;
  double azimuth_end_rad = 0.0;
  double min_range_m = 0.0;
  double max_range_m = 0.0;

  [[nodiscard]] std::size_t num_rays() const { return elevations_rad.size() * static_cast<std::size_t>(num_columns); }
  /// Fraction of the scan period at which column j fires, in [0, 1).
  [[nodiscard]] double column_time_fraction(int column) const {
    return static_cast<double>(column) / static_cast<double>(num_columns);
  }
  /// Unit ray direction of (column, channel) in the sensor frame.
  [[nodiscard]] Eigen::Vector3d direction(int column, std::size_t channel) const;
};

/// Evenly spaced elevations from lowest to highest (inclusive), one per channel.
std::vector<double> uniform_elevations_rad(std::size_t channels, double lowest_rad, double highest_rad);

/// A spinning sensor (clockwise seen from above, starting behind the sensor, like common
/// mechanical LiDARs).
LidarSensor spinning_lidar(std::uint8_t id, const SE3& T_lidar_sensor, std::vector<double> elevations_rad,
                           int num_columns, double min_range_m, double max_range_m);

/// A raster (solid-state style) sensor sweeping its horizontal field of view from left to
/// right, centred on its x axis.
LidarSensor raster_lidar(std::uint8_t id, const SE3& T_lidar_sensor, std::vector<double> elevations_rad,
                         int num_columns, double horizontal_fov_rad, double min_range_m, double max_range_m);

}  // namespace farlio::sim
