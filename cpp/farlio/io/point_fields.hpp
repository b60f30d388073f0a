#pragma once
// Mapping the fields of a point cloud file onto the channels of a Scan, shared by the readers.
//
//   x y z                       -> points (required)
//   intensity, scalar_intensity -> intensity (first found)
//   t, time, timestamp          -> time_s (first found); floating point values are seconds,
//                                  integer values are nanoseconds (Ouster's uint32 `t`)
//   sensor_id                   -> sensor_id
// Every other field is skipped whatever its type or count.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/types.hpp"
#include "farlio/io/scalar.hpp"

namespace farlio::io {

struct FieldSpec {
  std::string name;
  ScalarType type;
  std::size_t count = 1;  ///< PCD COUNT: values per point
};

/// Indices into the field list of the fields that feed a Scan.
struct ChannelMap {
  std::size_t x = 0, y = 0, z = 0;
  std::optional<std::size_t> intensity, time, sensor_id;
  bool time_in_ns = false;  ///< the time field holds integer nanoseconds
};

/// Throws InputError naming `file` if x, y or z is missing or a used field has a COUNT other than 1.
[[nodiscard]] ChannelMap map_channels(const std::vector<FieldSpec>& fields, const std::string& file);

/// A sensor_id value as stored: throws InputError naming `file`, the point and the value unless
/// it is an integer in 0..255.
[[nodiscard]] std::uint8_t sensor_id_value(double v, std::size_t point, const std::string& file);

/// Builds a scan of `n` points; get(i, field_index) returns point i's value of a field (element 0).
template <class Get>
Scan assemble_scan(std::size_t n, const ChannelMap& m, const std::string& file, Get&& get) {
  Scan s;
  s.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.points[i] =
        Vec3f(static_cast<float>(get(i, m.x)), static_cast<float>(get(i, m.y)), static_cast<float>(get(i, m.z)));
  }
  if (m.intensity) {
    s.intensity.resize(n);
    for (std::size_t i = 0; i < n; ++i) s.intensity[i] = static_cast<float>(get(i, *m.intensity));
  }
  if (m.time) {
    s.time_s.resize(n);
    const double divisor = m.time_in_ns ? kNsPerS : 1.0;
    for (std::size_t i = 0; i < n; ++i) s.time_s[i] = static_cast<float>(get(i, *m.time) / divisor);
  }
  if (m.sensor_id) {
    s.sensor_id.resize(n);
    for (std::size_t i = 0; i < n; ++i) s.sensor_id[i] = sensor_id_value(get(i, *m.sensor_id), i, file);
  }
  return s;
}

}  // namespace farlio::io
