#include "farlio/sim/lidar_model.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace farlio::sim {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Livox Avia class: forward, 70.4° x 77.2°, 240k points/s from 6 lasers, 1-190 m (10 % reflectivity).
// The two prism rates are incommensurate (the rose never closes) and make about 300 petal passes a
// second: in 0.1 s the rosette covers the field of view at about 2° between lines.
constexpr double kAviaHorizontalFov_rad = 70.4 * kDeg, kAviaVerticalFov_rad = 77.2 * kDeg;
constexpr double kAviaPointsPerSecond = 240'000.0;
constexpr int kAviaLasers = 6;
constexpr double kAviaLaserSpacing_rad = 0.6 * kDeg;
constexpr double kAviaRateA_rad_s = kTwoPi * 173.1, kAviaRateB_rad_s = kTwoPi * 127.3;
constexpr double kAviaMinRange_m = 1.0, kAviaMaxRange_m = 190.0;

// Livox Mid-360 class: 360° x 59° (-7° to 52°), 200k points/s from 4 lasers, 0.1-70 m. About 10
// turns a second; the elevation sweeps ~1300 times a second, incommensurate with the spin.
constexpr double kMid360LowElevation_rad = -7.0 * kDeg, kMid360HighElevation_rad = 52.0 * kDeg;
constexpr double kMid360PointsPerSecond = 200'000.0;
constexpr int kMid360Lasers = 4;
constexpr double kMid360SpinRate_rad_s = kTwoPi * 10.37, kMid360SweepRate_rad_s = kTwoPi * 1313.7;
constexpr double kMid360MinRange_m = 0.1, kMid360MaxRange_m = 70.0;

struct SpinningHead {
  std::size_t channels;
  double lowest_deg, highest_deg;
  double firings_per_second;  // columns per turn at 10 Hz, times 10
  double min_range_m, max_range_m;
};
constexpr SpinningHead kVlp16{16, -15.0, 15.0, 18'000.0, 0.5, 100.0};
constexpr SpinningHead kHdl32{32, -30.67, 10.67, 22'500.0, 1.0, 100.0};
constexpr SpinningHead kOs128{128, -22.5, 22.5, 10'240.0, 0.3, 120.0};

int firings_per_scan(double firings_per_second, double lidar_rate_hz) {
  if (!(lidar_rate_hz > 0.0)) throw std::invalid_argument("lidar_model: lidar_rate_hz must be positive");
  return std::max(1, static_cast<int>(std::lround(firings_per_second / lidar_rate_hz)));
}

LidarSensor head(const SpinningHead& h, std::uint8_t id, const SE3& T, double lidar_rate_hz) {
  return spinning_lidar(id, T, uniform_elevations_rad(h.channels, h.lowest_deg * kDeg, h.highest_deg * kDeg),
                        firings_per_scan(h.firings_per_second, lidar_rate_hz), h.min_range_m, h.max_range_m);
}

/// 0 at x = 0, 1 at x = pi, 0 again at 2 pi: a triangle wave of period 2 pi.
double triangle(double x) {
  const double u = std::fmod(x / std::numbers::pi, 2.0);
  const double v = u < 0.0 ? u + 2.0 : u;
  return v <= 1.0 ? v : 2.0 - v;
}

Eigen::Vector3d from_azimuth_elevation(double az, double el) {
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}
}  // namespace

Eigen::Vector3d LidarSensor::direction(int column, std::size_t channel, std::size_t scan_index) const {
  if (!pattern) {
    const double az = azimuth_begin_rad + (azimuth_end_rad - azimuth_begin_rad) * column_time_fraction(column);
    return from_azimuth_elevation(az, elevations_rad[channel]);
  }
  const NonRepetitivePattern& p = *pattern;
  const double firing = static_cast<double>(scan_index) * num_columns + column;
  const double t = firing / p.firing_rate_hz;
  const double offset = p.channel_offsets_rad[channel];
  if (p.kind == NonRepetitivePattern::Kind::Rosette) {
    const double half = 0.5 * p.radius_rad;
    const double x = half * (std::cos(p.rate_a_rad_s * t) + std::cos(p.rate_b_rad_s * t));
    const double y = half * (std::sin(p.rate_a_rad_s * t) - std::sin(p.rate_b_rad_s * t));
    return from_azimuth_elevation(p.azimuth_scale * x, y + offset);
  }
  const double el =
      p.elevation_low_rad + (p.elevation_high_rad - p.elevation_low_rad) * triangle(p.rate_b_rad_s * t + offset);
  return from_azimuth_elevation(-p.rate_a_rad_s * t + offset, el);
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
  LidarSensor l;
  l.id = id;
  l.T_lidar_sensor = T_lidar_sensor;
  l.elevations_rad = std::move(elevations_rad);
  l.num_columns = num_columns;
  l.azimuth_begin_rad = std::numbers::pi;
  l.azimuth_end_rad = -std::numbers::pi;
  l.min_range_m = min_range_m;
  l.max_range_m = max_range_m;
  return l;
}

LidarSensor raster_lidar(std::uint8_t id, const SE3& T_lidar_sensor, std::vector<double> elevations_rad,
                         int num_columns, double horizontal_fov_rad, double min_range_m, double max_range_m) {
  LidarSensor l = spinning_lidar(id, T_lidar_sensor, std::move(elevations_rad), num_columns, min_range_m, max_range_m);
  l.azimuth_begin_rad = 0.5 * horizontal_fov_rad;
  l.azimuth_end_rad = -0.5 * horizontal_fov_rad;
  return l;
}

LidarModel parse_lidar_model(const std::string& name) {
  for (const LidarModel m : {LidarModel::Profile, LidarModel::Avia, LidarModel::Mid360, LidarModel::Vlp16,
                             LidarModel::Hdl32, LidarModel::Os128})
    if (name == lidar_model_name(m)) return m;
  throw std::invalid_argument("unknown LiDAR model '" + name + "' (valid: profile, avia, mid360, vlp16, hdl32, os128)");
}

std::string lidar_model_name(LidarModel model) {
  switch (model) {
    case LidarModel::Profile: return "profile";
    case LidarModel::Avia: return "avia";
    case LidarModel::Mid360: return "mid360";
    case LidarModel::Vlp16: return "vlp16";
    case LidarModel::Hdl32: return "hdl32";
    case LidarModel::Os128: return "os128";
  }
  return "profile";
}

LidarSensor lidar_model(LidarModel model, std::uint8_t id, const SE3& T_lidar_sensor, double lidar_rate_hz) {
  switch (model) {
    case LidarModel::Vlp16: return head(kVlp16, id, T_lidar_sensor, lidar_rate_hz);
    case LidarModel::Hdl32: return head(kHdl32, id, T_lidar_sensor, lidar_rate_hz);
    case LidarModel::Os128: return head(kOs128, id, T_lidar_sensor, lidar_rate_hz);
    case LidarModel::Avia:
    case LidarModel::Mid360: break;
    case LidarModel::Profile: throw std::invalid_argument("lidar_model: 'profile' names the profile's own sensors");
  }
  const bool avia = model == LidarModel::Avia;
  const int lasers = avia ? kAviaLasers : kMid360Lasers;
  NonRepetitivePattern p;
  p.firing_rate_hz = (avia ? kAviaPointsPerSecond : kMid360PointsPerSecond) / lasers;
  for (int k = 0; k < lasers; ++k)
    p.channel_offsets_rad.push_back(avia ? (k - 0.5 * (lasers - 1)) * kAviaLaserSpacing_rad : kTwoPi * k / lasers);
  if (avia) {
    p.kind = NonRepetitivePattern::Kind::Rosette;
    p.rate_a_rad_s = kAviaRateA_rad_s;
    p.rate_b_rad_s = kAviaRateB_rad_s;
    p.radius_rad = 0.5 * kAviaVerticalFov_rad;
    p.azimuth_scale = kAviaHorizontalFov_rad / kAviaVerticalFov_rad;
  } else {
    p.kind = NonRepetitivePattern::Kind::OscillatingSpin;
    p.rate_a_rad_s = kMid360SpinRate_rad_s;
    p.rate_b_rad_s = kMid360SweepRate_rad_s;
    p.elevation_low_rad = kMid360LowElevation_rad;
    p.elevation_high_rad = kMid360HighElevation_rad;
  }
  LidarSensor l;
  l.id = id;
  l.T_lidar_sensor = T_lidar_sensor;
  l.num_columns = firings_per_scan(p.firing_rate_hz, lidar_rate_hz);
  l.min_range_m = avia ? kAviaMinRange_m : kMid360MinRange_m;
  l.max_range_m = avia ? kAviaMaxRange_m : kMid360MaxRange_m;
  l.pattern = std::move(p);
  return l;
}

}  // namespace farlio::sim
