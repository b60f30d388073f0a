#pragma once
// LiDAR sensor models. A sensor fires num_columns firings per scan period, evenly spaced in time
// from the scan start; all channels of a firing fire at the same instant.
//  - Grid sensors (spinning heads, rasters) repeat their pattern every scan: firing j points at
//    azimuth az_begin + (az_end - az_begin) * j / num_columns in the sensor frame (a spinning
//    sensor sweeps a full turn, a raster sensor its horizontal field of view) and channel k at
//    elevations_rad[k].
//  - Non-repetitive sensors (Livox) follow a pattern in time that never repeats: the directions of
//    a firing depend on its instant since the sequence start, so that scan after scan fills the
//    field of view. A rosette (Avia: two prisms turning at incommensurate rates) or a spinning head
//    whose elevation oscillates at a rate incommensurate with its spin (Mid-360).
// Sensors are mounted in the (merged) LiDAR frame. lidar_model() builds the named models of real
// sensors that SimConfig::lidar_model puts on a profile's vehicle in place of its own.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio::sim {

/// The time pattern of a non-repetitive sensor (angles in rad, rates in rad/s).
struct NonRepetitivePattern {
  enum class Kind {
    /// direction (az, el) = r/2 e^{i a t} + r/2 e^{-i b t} (+ the channel's offset), az scaled by
    /// azimuth_scale: the rose of two counter-rotating prisms, within radius r of the axis
    Rosette,
    /// az = -a t + the channel's phase (clockwise, as spinning heads), el sweeping
    /// [elevation_low, elevation_high] as a triangle wave of rate b (+ the channel's phase)
    OscillatingSpin,
  };
  Kind kind = Kind::Rosette;
  double firing_rate_hz = 0.0;  ///< firings per second (num_columns of a scan = this / scan rate)
  double rate_a_rad_s = 0.0;
  double rate_b_rad_s = 0.0;
  double radius_rad = 0.0;                                   ///< Rosette
  double azimuth_scale = 1.0;                                ///< Rosette: horizontal over vertical field of view
  double elevation_low_rad = 0.0, elevation_high_rad = 0.0;  ///< OscillatingSpin
  /// per channel: Rosette, its elevation offset (rad); OscillatingSpin, its phase (rad)
  std::vector<double> channel_offsets_rad;
};

struct LidarSensor {
  std::uint8_t id = 0;
  SE3 T_lidar_sensor;                  ///< the sensor's pose in the LiDAR frame named by T_imu_lidar
  std::vector<double> elevations_rad;  ///< grid sensors: one per channel
  int num_columns = 0;                 ///< firings per scan
  double azimuth_begin_rad = 0.0;
  double azimuth_end_rad = 0.0;
  double min_range_m = 0.0;
  double max_range_m = 0.0;
  std::optional<NonRepetitivePattern> pattern;  ///< set: a non-repetitive sensor

  [[nodiscard]] std::size_t num_channels() const {
    return pattern ? pattern->channel_offsets_rad.size() : elevations_rad.size();
  }
  [[nodiscard]] std::size_t num_rays() const { return num_channels() * static_cast<std::size_t>(num_columns); }
  /// Fraction of the scan period at which firing j fires, in [0, 1).
  [[nodiscard]] double column_time_fraction(int column) const {
    return static_cast<double>(column) / static_cast<double>(num_columns);
  }
  /// Unit ray direction of (firing, channel) of scan scan_index in the sensor frame (grid sensors:
  /// the same in every scan).
  [[nodiscard]] Eigen::Vector3d direction(int column, std::size_t channel, std::size_t scan_index = 0) const;
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

/// The sensors SimConfig::lidar_model can put on a profile's vehicle: its own (Profile), Livox's
/// non-repetitive Avia (forward, 70° x 77° rosette, 240k points/s) and Mid-360 (360° x 59°,
/// 200k points/s), and spinning heads of 16, 32 and 128 beams (VLP-16, HDL-32E, OS1-128 classes).
enum class LidarModel { Profile, Avia, Mid360, Vlp16, Hdl32, Os128 };

/// "profile" | "avia" | "mid360" | "vlp16" | "hdl32" | "os128"; throws std::invalid_argument
/// listing the valid names.
LidarModel parse_lidar_model(const std::string& name);
std::string lidar_model_name(LidarModel model);

/// One sensor of the named model (not Profile) at T_lidar_sensor, its firings per scan for a
/// scan rate of lidar_rate_hz (the model's points per second at any scan rate).
LidarSensor lidar_model(LidarModel model, std::uint8_t id, const SE3& T_lidar_sensor, double lidar_rate_hz);

}  // namespace farlio::sim
