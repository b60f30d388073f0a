#pragma once
// sensor_msgs/PointCloud2 bytes into float32 points, intensities and per-point times, in one pass
// per channel over the message's data, without an intermediate copy: the bulk part of
// farlio.datasets.pointcloud2.decode, which the bag loader and the ROS 2 node share.
//
// The caller picks the fields (the intensity and time field names, the time unit: the detection
// rules stay in farlio.datasets.pointcloud2); this checks the layout against the data, reads any
// PointField datatype in either byte order, drops the points at the origin (no return) and turns
// the time field into offsets (s) from the header stamp.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "farlio/core/types.hpp"

namespace farlio::io {

/// sensor_msgs/PointField datatype codes.
enum class PointFieldType : std::uint8_t {
  Int8 = 1,
  Uint8 = 2,
  Int16 = 3,
  Uint16 = 4,
  Int32 = 5,
  Uint32 = 6,
  Float32 = 7,
  Float64 = 8,
};

/// One sensor_msgs/PointField. Signed 64-bit so that a bad message's values reach the checks.
struct PointCloud2Field {
  std::string name;
  std::int64_t offset = 0;    ///< bytes from the start of a point
  std::int64_t datatype = 0;  ///< a PointFieldType code
  std::int64_t count = 1;     ///< values of the field per point; 0 is read as 1 (as drivers write it)
};

/// The layout of a sensor_msgs/PointCloud2's data.
struct PointCloud2Layout {
  std::int64_t width = 0;
  std::int64_t height = 0;
  std::int64_t point_step = 0;
  std::int64_t row_step = 0;  ///< 0: width * point_step
  bool big_endian = false;
  std::vector<PointCloud2Field> fields;
};

/// What to read besides x, y, z, and how per-point times become offsets from the header stamp:
/// a time value v (in the field's unit) is an absolute time when min(v) * ns_per_unit / 1e9 >
/// absolute_time_min_s over the cloud, and then its offset is v - header; else v is the offset.
struct PointCloud2Request {
  std::string intensity_field;  ///< empty: none
  std::string time_field;       ///< empty: none
  std::int64_t time_ns_per_unit = 1;
  std::int64_t header_ns = 0;
  double header_s = 0.0;  ///< header_ns in s, correctly rounded (the caller's division)
  double absolute_time_min_s = 0.0;
};

/// A decoded cloud. The time statistics are over the kept points (NaN when a time is NaN).
struct PointCloud2Points {
  std::vector<Vec3f> points;     ///< the points not at the origin, in data order
  std::vector<float> intensity;  ///< one per point, or empty (no intensity field)
  std::vector<double> offset_s;  ///< per-point time minus the header stamp, or empty (no time field)
  bool has_time = false;
  bool absolute_time = false;  ///< the time field holds absolute times
  double time_min = 0.0;       ///< smallest and largest raw value of the time field
  double time_max = 0.0;
  double offset_min_s = 0.0;  ///< smallest and largest offset_s
  double offset_max_s = 0.0;
};

/// Decodes `data` laid out as `layout`. Throws InputError starting with `where` for a missing x, y
/// or z, an unknown datatype, a field past point_step, a used field with a count other than 1, a
/// named field that is missing, or data too short for width x height points. A field name that
/// appears twice refers to its first occurrence.
[[nodiscard]] PointCloud2Points decode_pointcloud2(const PointCloud2Layout& layout, std::span<const std::uint8_t> data,
                                                   const PointCloud2Request& request, const std::string& where);

}  // namespace farlio::io
