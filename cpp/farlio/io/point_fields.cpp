#include "farlio/io/point_fields.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "farlio/core/error.hpp"

namespace farlio::io {
namespace {

std::optional<std::size_t> find_field(const std::vector<FieldSpec>& fields, std::string_view name) {
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (fields[k].name == name) return k;
  }
  return std::nullopt;
}

template <std::size_t N>
std::optional<std::size_t> find_first(const std::vector<FieldSpec>& fields,
                                      const std::array<std::string_view, N>& names) {
  for (auto name : names) {
    if (auto k = find_field(fields, name)) return k;
  }
  return std::nullopt;
}

}  // namespace

ChannelMap map_channels(const std::vector<FieldSpec>& fields, const std::string& file) {
  constexpr std::array<std::string_view, 2> kIntensityNames = {"intensity", "scalar_intensity"};
  constexpr std::array<std::string_view, 3> kTimeNames = {"t", "time", "timestamp"};
  ChannelMap m;
  auto require = [&](std::string_view name) {
    const auto k = find_field(fields, name);
    if (!k) throw InputError(file + ": no field '" + std::string(name) + "' (x, y and z are required)");
    return *k;
  };
  m.x = require("x");
  m.y = require("y");
  m.z = require("z");
  m.intensity = find_first(fields, kIntensityNames);
  m.time = find_first(fields, kTimeNames);
  m.sensor_id = find_field(fields, "sensor_id");
  for (const auto& k : {std::optional<std::size_t>(m.x), std::optional<std::size_t>(m.y),
                        std::optional<std::size_t>(m.z), m.intensity, m.time, m.sensor_id}) {
    if (k && fields[*k].count != 1) {
      throw InputError(file + ": field '" + fields[*k].name + "' has COUNT " + std::to_string(fields[*k].count) +
                       " (expected 1)");
    }
  }
  m.time_in_ns = m.time && fields[*m.time].type.is_integer();
  return m;
}

std::uint8_t sensor_id_value(double v, std::size_t point, const std::string& file) {
  constexpr double kMaxSensorId = std::numeric_limits<std::uint8_t>::max();
  if (!(v >= 0.0 && v <= kMaxSensorId) || std::floor(v) != v) {
    throw InputError(file + ": field 'sensor_id' of point " + std::to_string(point) + " is " + std::to_string(v) +
                     ", not an integer in 0..255");
  }
  return static_cast<std::uint8_t>(v);
}

}  // namespace farlio::io
