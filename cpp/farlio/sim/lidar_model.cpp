#include "farlio/sim/lidar_model.hpp"

#include <cmath>
#include <numbers>

namespace farlio::sim {

Eigen::Vector3d LidarSensor::direction(int column, std::size_t channel) const {
  const double az = azimuth_begin_rad + (azimuth_end_rad - azimuth_begin_rad) * column_time_fraction(column);
  const double el = elevations_rad[channel];
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

std::vector<double> uniform_elevations_rad(std::size_t channels, double lowest_rad, double highest_rad) {
  std::vector<double> el(channels);
  for (std::size_t k = 0; k < channels; ++k)
    el[k] = channels == 1
                ? lowest_rad
                : lowest_rad + (highest_rad - lowest_rad) * static_cast<double>(k) / static_cast<double>(channels - 1);
  return el;
}

LidarSensor spinning_lidar(std::uint8_t id, const SE3& T_lidar_sensor, std::vector<double> elevations_rad,
                           int num_columns, double min_range_m, double max_range_m) {
  return {id,          T_lidar_sensor, std::move(elevations_rad), num_columns, std::numbers::pi, -std::numbers::pi,
          min_range_m, max_range_m};
}

LidarSensor raster_lidar(std::uint8_t id, const SE3& T_lidar_sensor, std::vector<double> elevations_rad,
                         int num_columns, double horizontal_fov_rad, double min_range_m, double max_range_m) {
  return {id,
          T_lidar_sensor,
          std::move(elevations_rad),
          num_columns,
          0.5 * horizontal_fov_rad,
          -0.5 * horizontal_fov_rad,
          min_range_m,
          max_range_m};
}

}  // namespace farlio::sim
